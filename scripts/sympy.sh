#!/usr/bin/env bash
# The independent sympy verification: creates (or reuses) a virtual
# environment with the pinned requirements of tests/sympy, exports every
# reference model with `cargo run -p constrained-tests --example
# sympy_export` (or, when CONSTRAINED_EXAMPLES_DIR names a folder of built
# examples, as scripts/test.sh sets it, from there), and runs the pytest
# suite. Writes under the target directory (CARGO_TARGET_DIR when set).
# Fails loudly when Python or a requirement cannot be had.
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

target=$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
sympy_export=(cargo run --quiet -p constrained-tests --example sympy_export --)
op_counts=(cargo run --quiet -p constrained-codegen --example op_counts --)
if [ -n "${CONSTRAINED_EXAMPLES_DIR:-}" ]; then
    sympy_export=("$CONSTRAINED_EXAMPLES_DIR/sympy_export")
    op_counts=("$CONSTRAINED_EXAMPLES_DIR/op_counts")
fi
export CONSTRAINED_TARGET_DIR="$target" # where the suite writes (test_op_counts.py)
export CONSTRAINED_SYSTEMS_JSON="$target/sympy/systems.json"
"${sympy_export[@]}" "$CONSTRAINED_SYSTEMS_JSON"
# The generated accelerations' operation counts (tests/sympy/test_op_counts.py).
export CONSTRAINED_OP_COUNTS_JSON="$target/sympy/op_counts.json"
"${op_counts[@]}" "$CONSTRAINED_OP_COUNTS_JSON" > /dev/null
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
