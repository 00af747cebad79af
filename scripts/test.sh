#!/usr/bin/env bash
# Runs every test of the project: unit, integration, property, snapshot,
# compile-fail (trybuild) and doc tests; the benches once each in test mode
# so that they cannot rot; every example, briefly; the independent sympy
# suite (in a virtual environment with pinned requirements); and the
# embedded run (firmware on an emulated Cortex-M4F under QEMU, compared
# with the host). Ends with a summary of what ran, stage by stage.
# Needs cargo and python3; installs the thumbv7em target, QEMU (Debian
# package) and the Python requirements when missing.
#
# One build serves every stage: the workspace's tests, benches and
# examples are compiled once, in the test profile, and the examples and
# the sympy export are run from that build rather than rebuilt in another
# profile. Everything it writes goes to the target directory
# (CARGO_TARGET_DIR when set), and no tracked file changes (`--locked`).
# Each stage's full output is in <target>/test-logs/; the console shows
# what ran and, on a failure, that stage's log.
set -euo pipefail
cd "$(dirname "$0")/.."

# A plain log: no colours, progress bars or interactive prompts.
export CARGO_TERM_COLOR=never CARGO_TERM_PROGRESS_WHEN=never TERM=dumb NO_COLOR=1 PY_COLORS=0
export DEBIAN_FRONTEND=noninteractive
# A fresh clone gains nothing from incremental caches (CPU and disk).
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"
export INSTA_UPDATE=no # snapshots are compared, never written, here
# Property tests draw their cases from a fixed seed here, so that a run is
# reproducible and a failure seen once is seen on every machine. Fresh
# seeds are for scripts/explore.sh (or set PROPTEST_RNG_SEED yourself).
export PROPTEST_RNG_SEED="${PROPTEST_RNG_SEED:-20261121}"

target=$(cargo metadata --format-version 1 --no-deps --locked |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
logs="$target/test-logs"
mkdir -p "$logs"
summary="$logs/summary.txt"
: > "$summary"
run_start=$(date +%s.%N)

# Sets cpu_seconds to the CPU time (user + sys) of every finished child so
# far: `times` runs in this shell, since a command substitution's subshell
# would report children of its own.
cpu_now() {
    # One file per shell: two stages run side by side in subshells.
    local file="$logs/.times.$BASHPID"
    times > "$file"
    cpu_seconds=$(python3 -c 'import re, sys
text = open(sys.argv[1]).read().splitlines()[-1]
print(sum(float(m) * 60 + float(s) for m, s in re.findall(r"(\d+)m([\d.]+)s", text)))' "$file")
    rm -f "$file"
}

# stage NAME LOG COMMAND...: runs COMMAND with its output in LOG, times it,
# and on failure prints the log and stops.
stage() {
    local name=$1 log=$2
    shift 2
    local start cpu_start
    start=$(date +%s.%N)
    cpu_now
    cpu_start=$cpu_seconds
    echo "== $name"
    if ! "$@" > "$log" 2>&1; then
        cat "$log"
        echo "== FAILED: $name (log: $log)" >&2
        exit 1
    fi
    cpu_now
    python3 - "$name" "$start" "$(date +%s.%N)" "$cpu_start" "$cpu_seconds" >> "$summary" <<'PY'
import sys
name, start, end, cpu_start, cpu_end = sys.argv[1], *map(float, sys.argv[2:])
print(f"{name}\t{end - start:.0f}\t{cpu_end - cpu_start:.0f}")
PY
}

echo "property tests: PROPTEST_RNG_SEED=$PROPTEST_RNG_SEED; logs in $logs"
# `cargo test` without target flags builds the examples once, as the
# programs they are (`--all-targets` or `--examples` would build each of
# them a second time, as a test harness with no tests in it: two
# expansions and two compilations of every example's model), at
# debug/examples/NAME, where the stages below run them; `--benches` adds
# the benches in test mode, to be run once each.
build_all() {
    cargo test --locked --workspace --no-run &&
        cargo test --locked --workspace --benches --no-run
}
stage "build: tests, benches and examples (test profile)" "$logs/build.log" build_all
# After the build, the stages run two at a time, in lanes that share the
# two cores well: the tests (mostly one test binary, trybuild's and the
# fuzz harness's builds at a time) beside the sympy suite (one Python
# process, about a minute and a half) followed by the embedded run (its
# own build, in a target directory of its own so that the two cargo runs
# never wait on one lock, then QEMU); then the doc tests, the std-feature
# crate and the examples. A pair fails when either lane does; each stage's
# output stays in its own log.
both() {
    local first second failed=0
    "$1" & first=$!
    "$2" & second=$!
    wait "$first" || failed=1
    wait "$second" || failed=1
    return "$failed"
}

examples="$target/debug/examples"
# The doc tests are the second pair's: here every target with tests
# (`--tests`: the libraries' unit tests, the integration tests, not the
# harnesses that `test = false` leaves out) and the benches.
tests_stage() {
    stage "tests: unit, integration, property, snapshot, compile-fail; benches once" "$logs/tests.log" \
        cargo test --locked --workspace --tests --benches
}
# The sympy export and the operation counts from the same build.
sympy_stage() {
    CONSTRAINED_EXAMPLES_DIR="$examples" stage "sympy: the independent suite" "$logs/sympy.log" \
        bash scripts/sympy.sh
}
# The second lane: the sympy suite, then the embedded run (below).
sympy_then_embedded() {
    sympy_stage && embedded_stage
}

# Every example, briefly, so that none can rot (the main one checks itself
# and exits non-zero on disagreement); the LQR example at full length: it
# exits non-zero unless both forms of the cart-pole balance and their gains
# agree. Run from the build above.
run_examples() {
    for example in appell spherical_pendulum double_pendulum bead_on_hoop chaplygin_sleigh slider_crank two_link_arm crane spinning_top panda quadruped quadruped_balance five_bar rimless_wheel pendulum_wall compass_gait; do
        echo "-- $example"
        # `|| return`: set -e does not stop a function run as an `if`'s
        # condition (stage's), and a failing example went unnoticed.
        "$examples/$example" --duration 0.5 --out "$target/plots" || return 1
    done
    echo "-- cart_pole_lqr"
    "$examples/cart_pole_lqr" --out "$target/plots" || return 1
}
host_stages() {
    stage "doc tests: the crates, the guides and the README" "$logs/doctests.log" \
        cargo test --locked --workspace --doc
    # A user's crate with `features = ["std"]`, outside the workspace (whose
    # dev-dependencies would enable std for it).
    stage "std feature: a user's crate outside the workspace" "$logs/std-feature.log" \
        cargo test --locked --manifest-path tests/std-feature/Cargo.toml
    stage "examples: 17, plots in $target/plots" "$logs/examples.log" run_examples
}
embedded_stage() {
    CARGO_TARGET_DIR="$target/firmware" stage "embedded: firmware under QEMU against the host" "$logs/embedded.log" \
        bash scripts/embedded.sh
}
both tests_stage sympy_then_embedded || exit 1
host_stages || exit 1

python3 scripts/test_summary.py "$logs" "$summary" "$run_start"
