#!/usr/bin/env bash
# Before/after in one run: builds benches/acceleration.rs at a base revision
# (in a git worktree under the target directory) and at the working tree,
# then runs the two binaries alternately, ROUNDS times each, on the same
# benchmarks, and prints the median times side by side with their ratio.
# Alternating spreads the machine's noise over both sides; both binaries are
# built aligned, as scripts/benchmarks.sh builds them (scripts/aligned.sh).
#
#   scripts/compare_acceleration.sh BASE_REV [FILTER] [ROUNDS]
#
# FILTER is a criterion filter (default: every `acceleration` benchmark of
# the models, the chains and Appell's particle). Not part of the test
# command; takes a few minutes (two release builds).
set -euo pipefail
cd "$(dirname "$0")/.."
base_rev=${1:?usage: compare_acceleration.sh BASE_REV [FILTER] [ROUNDS]}
filter=${2:-'^(models/.*/acceleration|chain_acceleration/|appell_acceleration_12_states/generated)'}
rounds=${3:-2}
source scripts/aligned.sh
export RUSTFLAGS="$ALIGNED_RUSTFLAGS"
target=$ALIGNED_TARGET_DIR
base_dir="$target/compare/base"

executable() { # prints the bench executable cargo builds in $1 with target dir $2
    # The benches are the package constrained-tests' since it exists
    # (tests/Cargo.toml), the root package's before.
    local package=()
    [ -f "$1/tests/Cargo.toml" ] && package=(-p constrained-tests)
    (cd "$1" && CARGO_TARGET_DIR="$2" cargo bench "${package[@]}" --bench acceleration --no-run \
        --message-format=json 2>/dev/null |
        python3 -c 'import json,sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["target"]["name"] == "acceleration":
        print(m["executable"])')
}

mkdir -p "$target/compare"
if [ -n "${BASE_EXE:-}" ]; then # a base binary built before (same revision)
    base_exe=$BASE_EXE
else
    rm -rf "$base_dir"
    git worktree prune
    git worktree add --detach "$base_dir" "$base_rev" > /dev/null
    trap 'git worktree remove --force "$base_dir" > /dev/null 2>&1 || true' EXIT
    echo "building $base_rev (release)…" >&2
    base_exe=$(executable "$base_dir" "$(realpath "$target")/compare/target-base")
fi
echo "building the working tree (release)…" >&2
head_exe=$(executable . "$(realpath "$target")")
out="$target/compare/runs"
mkdir -p "$out"
for round in $(seq "$rounds"); do
    for side in base head; do
        exe=$base_exe
        [ "$side" = head ] && exe=$head_exe
        "$exe" --bench "$filter" --warm-up-time 1 --measurement-time 3 --noplot \
            > "$out/$side-$round.log" 2> /dev/null
    done
done
python3 - "$out" "$rounds" <<'EOF'
import re, sys, statistics, pathlib
out, rounds = pathlib.Path(sys.argv[1]), int(sys.argv[2])
unit = {"ps": 1e-3, "ns": 1.0, "µs": 1e3, "us": 1e3, "ms": 1e6, "s": 1e9}
def medians(side):
    """Criterion prints `name  time: [low median high]`, or the name on a
    line of its own and `time:` indented on the next."""
    times, name = {}, None
    for r in range(1, rounds + 1):
        for line in (out / f"{side}-{r}.log").read_text().splitlines():
            m = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+)", line)
            if m:
                key = line[: m.start()].strip() or name
                times.setdefault(key, []).append(float(m.group(1)) * unit[m.group(2)])
            elif line.strip() and not line[0].isspace():
                name = line.strip()
    return {k: statistics.median(v) for k, v in times.items()}
base, head = medians("base"), medians("head")
print(f"{'benchmark':52} {'before':>11} {'after':>11} {'after/before':>13}")
for name in sorted(set(base) & set(head)):
    b, h = base[name], head[name]
    print(f"{name:52} {b:>9.2f}ns {h:>9.2f}ns {h / b:>13.3f}")
EOF
