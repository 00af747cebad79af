#!/usr/bin/env bash
# Runs every benchmark side by side in one run and writes BENCHMARKS.md:
# the generated code against hand-written eq. 32, dynamic nalgebra and sympy
# lambdify on Appell's particle; the N-link chain (both equations of motion,
# RK4 steps); macro expansion time and generated code size against N;
# Lagrange's equations from energies (the N-link pendulum in joint angles)
# against sympy's LagrangesMethod; RK4 steps with projection; the M(q)
# models against a dense KKT solve; the Jacobian of q̈; Pinocchio and
# MuJoCo on the chain and the four-bar, and robots read from URDF as
# written (the Panda, the UR5, TALOS, the xArm7, the Kinova Jaco 2, the
# Unitree G1) against Pinocchio's aba, crba and rnea (benches/peers/run.sh;
# event location: runs with events that never trigger against runs without,
# and the evaluations per located crossing (benches/events.rs); the impact
# maps per impact (benches/impact.rs);
# PEERS=0 skips them, and a failure there leaves their rows out without
# stopping the rest). Benchmarks run pinned to one core where taskset exists.
# Takes half an hour to an hour on two cores (Pinocchio's templates,
# when not yet compiled, take minutes more).
set -euo pipefail
cd "$(dirname "$0")/.."
# Outputs go to cargo's target directory (CARGO_TARGET_DIR when set).
target=$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
export CONSTRAINED_TARGET_DIR="$target"
quick=(--warm-up-time 1 --measurement-time 3)

# Sets up the pinned Python environment, and counts the operations of the
# generated accelerations against sympy's cse on every model (the
# eight-constraint four-bar takes sympy minutes, so only here).
CONSTRAINED_OP_COUNTS_ALL=1 bash scripts/sympy.sh > /dev/null
pin=()
if command -v taskset > /dev/null; then pin=(taskset -c 1); fi
# The criterion binaries are built aligned (scripts/aligned.sh says why),
# their results still under $target/criterion.
source scripts/aligned.sh
aligned=(env "RUSTFLAGS=$ALIGNED_RUSTFLAGS" "CARGO_TARGET_DIR=$ALIGNED_TARGET_DIR"
    "CRITERION_HOME=$target/criterion")
# Only this run's results reach the report.
rm -rf "$target/criterion"
echo "== build the benchmarks"
"${aligned[@]}" cargo bench --quiet --no-run -p constrained-tests --bench acceleration --bench jacobian --bench projection --bench baumgarte --bench events --bench impact
"${aligned[@]}" cargo bench --quiet --no-run -p constrained-codegen --bench expand
echo "== criterion: generated code (benches/acceleration.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-tests --bench acceleration -- "${quick[@]}" > "$target/benchmarks-acceleration.log"
echo "== criterion: the Jacobian of q̈ (benches/jacobian.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-tests --bench jacobian -- "${quick[@]}" > "$target/benchmarks-jacobian.log"
echo "== criterion: projection (benches/projection.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-tests --bench projection -- "${quick[@]}" > "$target/benchmarks-projection.log"
echo "== criterion: Baumgarte-stabilized steps (benches/baumgarte.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-tests --bench baumgarte -- "${quick[@]}" > "$target/benchmarks-baumgarte.log"
echo "== criterion: event location (benches/events.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-tests --bench events -- "${quick[@]}" > "$target/benchmarks-events.log"
echo "== criterion: impact maps (benches/impact.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-tests --bench impact -- "${quick[@]}" > "$target/benchmarks-impact.log"
echo "== criterion: macro expansion (codegen/benches/expand.rs)"
"${aligned[@]}" "${pin[@]}" cargo bench --quiet -p constrained-codegen --bench expand -- "${quick[@]}" > "$target/benchmarks-expand.log"
echo "== generated code size"
cargo run --quiet -p constrained-codegen --example expansion_size -- "$target/benchmarks/expansion.json"
echo "== sympy lambdify"
tests/sympy/.venv/bin/python benches/lambdify.py
echo "== sympy LagrangesMethod on the N-link pendulum in joint angles (up to 120 s per N)"
tests/sympy/.venv/bin/python benches/lagrange_sympy.py 120
echo "== factoring: rules against an e-graph (scripts/egg_compare.sh)"
mkdir -p "$target/benchmarks"
bash scripts/egg_compare.sh > "$target/benchmarks/egg.md"
rm -f "$target/benchmarks/peers.json"
if [ "${PEERS:-1}" != 0 ]; then
  echo "== peers: Pinocchio and MuJoCo, and the robots (benches/peers/run.sh)"
  bash benches/peers/run.sh > /dev/null || echo "   the peers failed (see above): their rows are left out"
fi
echo "== report"
python3 benches/report.py
