#!/usr/bin/env bash
# Runs every benchmark side by side in one run and writes BENCHMARKS.md:
# the generated code against hand-written eq. 32, dynamic nalgebra and sympy
# lambdify on Appell's particle; the N-link chain (both equations of motion,
# RK4 steps); macro expansion time and generated code size against N;
# Lagrange's equations from energies (the N-link pendulum in joint angles)
# against sympy's LagrangesMethod; RK4 steps with projection; the M(q)
# models against a dense KKT solve; the Jacobian of q̈.
# Takes about five minutes on two cores.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=(--warm-up-time 1 --measurement-time 3)

bash scripts/sympy.sh > /dev/null # sets up the pinned Python environment
echo "== criterion: generated code (benches/acceleration.rs)"
cargo bench --quiet --bench acceleration -- "${quick[@]}" > target/benchmarks-acceleration.log
echo "== criterion: the Jacobian of q̈ (benches/jacobian.rs)"
cargo bench --quiet --bench jacobian -- "${quick[@]}" > target/benchmarks-jacobian.log
echo "== criterion: projection (benches/projection.rs)"
cargo bench --quiet --bench projection -- "${quick[@]}" > target/benchmarks-projection.log
echo "== criterion: macro expansion (codegen/benches/expand.rs)"
cargo bench --quiet -p constrained-codegen --bench expand -- "${quick[@]}" > target/benchmarks-expand.log
echo "== generated code size"
cargo run --quiet -p constrained-codegen --example expansion_size -- target/benchmarks/expansion.json
echo "== sympy lambdify"
tests/sympy/.venv/bin/python benches/lambdify.py
echo "== sympy LagrangesMethod on the N-link pendulum in joint angles (up to 120 s per N)"
tests/sympy/.venv/bin/python benches/lagrange_sympy.py 120
echo "== report"
python3 benches/report.py
