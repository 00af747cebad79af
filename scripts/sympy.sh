#!/usr/bin/env bash
# The independent sympy verification: creates (or reuses) a virtual
# environment with the pinned requirements of tests/sympy, exports every
# reference model with `cargo run --example sympy_export`, and runs the
# pytest suite. Fails loudly when Python or a requirement cannot be had.
# `--mutate` runs it on a deliberately wrong derivative, which must fail.
set -euo pipefail
cd "$(dirname "$0")/.."

python=${PYTHON:-python3}
if ! command -v "$python" >/dev/null; then
    echo "error: $python is not installed; the sympy suite needs Python 3.10 or newer" >&2
    exit 1
fi
venv=tests/sympy/.venv
requirements=tests/sympy/requirements.txt
stamp="$venv/.requirements.sha256"
wanted=$(sha256sum "$requirements" | cut -d' ' -f1)
if [ ! -x "$venv/bin/python" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$wanted" ]; then
    echo "setting up $venv with the pinned requirements"
    "$python" -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check -r "$requirements"
    echo "$wanted" > "$stamp"
fi
"$venv/bin/python" -c "import sympy, numpy, pytest" # loud if anything is missing

export CONSTRAINED_SYSTEMS_JSON="$PWD/target/sympy/systems.json"
cargo run --quiet --example sympy_export -- "$CONSTRAINED_SYSTEMS_JSON"
# The generated accelerations' operation counts (tests/sympy/test_op_counts.py).
export CONSTRAINED_OP_COUNTS_JSON="$PWD/target/sympy/op_counts.json"
cargo run --quiet -p constrained-codegen --example op_counts -- "$CONSTRAINED_OP_COUNTS_JSON" > /dev/null
if [ "${1:-}" = "--mutate" ]; then
    echo "== with a deliberately wrong derivative (b₁ of every system negated): this must fail"
    if CONSTRAINED_SYMPY_MUTATE=1 "$venv/bin/python" -m pytest tests/sympy -q -p no:cacheprovider; then
        echo "error: the suite passed on a wrong derivative" >&2
        exit 1
    fi
    echo "== the suite failed, as it must"
else
    "$venv/bin/python" -m pytest tests/sympy -q -p no:cacheprovider
fi
