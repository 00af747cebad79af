#!/usr/bin/env bash
# The peers' rows of BENCHMARKS.md: Pinocchio (C++) and MuJoCo (C), compiled
# against the headers and libraries of their Python wheels, on the same
# systems and states as the generated code; and the Robots rows, robots
# read from example-robot-data's URDFs as written (the Panda, the UR5,
# TALOS, the xArm7, the Kinova Jaco 2, the Unitree G1; the table is
# benches/peers/robots/build.rs; benches/peers/robots, our side and its
# times; benches/peers/robots.cpp, Pinocchio's, matched by joint name); and the
# Contacts rows, the quadruped, the Unitree Go1 (its URDF on a floating
# root) and the five-bar against Pinocchio's constraintDynamics and lcaba
# (benches/peers/robots/src/bin/contacts.rs, benches/peers/contacts.cpp), the
# Go1's ∂q̈ and ∂λ against computeConstraintDynamicsDerivatives too; and
# the Kinematics and derivatives rows, the Panda, the G1 and the Go1 with
# named frames against Pinocchio's frame placements, Jacobians and classical
# accelerations, centre of mass and its velocity, centroidal map and its
# time variation, RNEA and ABA derivatives
# (benches/peers/robots/src/bin/kinematics.rs, benches/peers/kinematics.cpp).
# The Robots rows also run Pinocchio traced into CasADi and emitted as C
# (benches/peers/casadi, its own virtual environment .venv-casadi) on the
# Panda, the UR5 and the G1. Each program checks its answer
# against the generated code's (chains/examples/peer_reference.rs) before it
# times anything, and exits with 1 if one disagrees.
#
# Sets up its own virtual environment (benches/peers/.venv); writes
# <target>/benchmarks/peers.json, robots.json, kinematics.json and
# contacts.json (one JSON object per line). Called by
# scripts/benchmarks.sh; not part of the test command. Pins the peers to one
# core (taskset, where there is one), as the script pins criterion.
set -euo pipefail
cd "$(dirname "$0")/../.."
here=benches/peers
target=$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
out=$target/peers
mkdir -p "$out" "$target/benchmarks"

if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
site=$("$here/.venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
prefix="$site/cmeel.prefix"
mujoco="$site/mujoco"
robot_data="$prefix/share/example-robot-data/robots"

# The same optimisation as the Rust side's release profile (-O3, no
# -march=native: neither side is built for this particular CPU). Pinocchio's
# CMake targets define the Boost limits its joint variant needs.
if [ ! -x "$out/pinocchio" ] || [ "$here/pinocchio.cpp" -nt "$out/pinocchio" ] || [ "$here/common.h" -nt "$out/pinocchio" ]; then
  echo "   compiling Pinocchio's side (header templates: about two minutes)"
  g++ -std=c++17 -O3 -DNDEBUG -w \
    -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION -DBOOST_MPL_LIMIT_LIST_SIZE=30 \
    -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
    -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    -I"$prefix/include" -I"$prefix/include/eigen3" "$here/pinocchio.cpp" -o "$out/pinocchio" \
    -L"$prefix/lib" -Wl,-rpath,"$prefix/lib" -lpinocchio_default
fi
# The robots' rows are optional: a failure to build them leaves them out
# (and the script's status 1) without losing the rows above.
robots_ok=1
if [ ! -x "$out/robots" ] || [ "$here/robots.cpp" -nt "$out/robots" ] || [ "$here/common.h" -nt "$out/robots" ] || [ "$here/robots.h" -nt "$out/robots" ]; then
  echo "   compiling Pinocchio's robots (its URDF parser's templates too: minutes)"
  rm -f "$out/robots"
  g++ -std=c++17 -O3 -DNDEBUG -w \
    -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION -DBOOST_MPL_LIMIT_LIST_SIZE=30 \
    -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
    -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    -I"$prefix/include" -I"$prefix/include/eigen3" -I"$prefix/include/urdfdom_headers" "$here/robots.cpp" -o "$out/robots" \
    -L"$prefix/lib" -Wl,-rpath,"$prefix/lib" -lpinocchio_parsers -lpinocchio_default -lurdfdom_model || robots_ok=0
fi
# The Kinematics and derivatives rows (frames, the centre of mass, the
# centroidal momentum, ∂τ and ∂q̈ of the Panda, the G1 and the Go1 from
# their URDFs) against Pinocchio's frame algorithms, centre of mass,
# centroidal algorithms, computeRNEADerivatives and computeABADerivatives;
# optional like the robots'.
kinematics_ok=1
if [ ! -x "$out/kinematics" ] || [ "$here/kinematics.cpp" -nt "$out/kinematics" ] || [ "$here/common.h" -nt "$out/kinematics" ] || [ "$here/robots.h" -nt "$out/kinematics" ]; then
  echo "   compiling Pinocchio's kinematics and ABA derivatives (its templates: minutes)"
  rm -f "$out/kinematics"
  g++ -std=c++17 -O3 -DNDEBUG -w \
    -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION -DBOOST_MPL_LIMIT_LIST_SIZE=30 \
    -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
    -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    -I"$prefix/include" -I"$prefix/include/eigen3" -I"$prefix/include/urdfdom_headers" "$here/kinematics.cpp" -o "$out/kinematics" \
    -L"$prefix/lib" -Wl,-rpath,"$prefix/lib" -lpinocchio_parsers -lpinocchio_default -lurdfdom_model || kinematics_ok=0
fi
# The Contacts rows (the quadruped and the Go1 on four feet, the five-bar loop) against
# Pinocchio's constrained dynamics; optional like the robots'.
contacts_ok=1
if [ ! -x "$out/contacts" ] || [ "$here/contacts.cpp" -nt "$out/contacts" ] || [ "$here/common.h" -nt "$out/contacts" ]; then
  echo "   compiling Pinocchio's constrained dynamics (its templates: minutes)"
  rm -f "$out/contacts"
  g++ -std=c++17 -O3 -DNDEBUG -w \
    -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION -DBOOST_MPL_LIMIT_LIST_SIZE=30 \
    -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
    -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    -I"$prefix/include" -I"$prefix/include/eigen3" -I"$prefix/include/urdfdom_headers" "$here/contacts.cpp" -o "$out/contacts" \
    -L"$prefix/lib" -Wl,-rpath,"$prefix/lib" -lpinocchio_parsers -lpinocchio_default -lurdfdom_model || contacts_ok=0
fi
if [ ! -x "$out/mujoco" ] || [ "$here/mujoco.c" -nt "$out/mujoco" ] || [ "$here/common.h" -nt "$out/mujoco" ]; then
  library=$(cd "$mujoco" && ls libmujoco.so.* | head -1)
  gcc -std=c11 -O3 -DNDEBUG -D_POSIX_C_SOURCE=200809L -I"$mujoco/include" "$here/mujoco.c" \
    -o "$out/mujoco" -L"$mujoco" -Wl,-rpath,"$mujoco" -l:"$library" -lm
fi

# Pinocchio traced into CasADi and emitted as C: a virtual environment of
# its own (its wheel pulls an older pin), the robots' aba, crba and rnea
# generated from our robots' reference file (by joint name), compiled with
# the harness at -O3 as the other peers.
casadi_generate() {
  local reference=$1 dir=$2 env="$here/.venv-casadi"
  if [ ! -x "$env/bin/python" ]; then
    python3 -m venv "$env" || return 1
  fi
  "$env/bin/pip" install --quiet --disable-pip-version-check -r "$here/casadi/requirements.txt" || return 1
  local site prefix
  site=$("$env/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
  prefix="$site/cmeel.prefix"
  LD_LIBRARY_PATH="$prefix/lib" PYTHONPATH=$(echo "$prefix"/lib/python3*/site-packages) \
    "$env/bin/python" "$here/casadi/generate.py" "$robot_data" "$reference" "$dir" panda ur5 g1 || return 1
  gcc -std=c11 -O3 -DNDEBUG -D_POSIX_C_SOURCE=200809L -I"$dir" "$here/casadi/harness.c" \
    "$dir/casadi_robots.c" -o "$dir/casadi" -lm
}

cargo run --quiet --release -p constrained-chains --example peer_reference -- "$out/reference.txt"
# The robots' crate (outside the workspace) reads the URDFs at compile
# time; built here, unpinned, and run pinned below.
export EXAMPLE_ROBOT_DATA="$robot_data"
cargo build --quiet --release --manifest-path "$here/robots/Cargo.toml" || { robots_ok=0; contacts_ok=0; kinematics_ok=0; }
pin=()
if command -v taskset > /dev/null; then pin=(taskset -c 1); fi
status=$((1 - robots_ok))
# The robots' binaries, built above (the crate's own target directory, or
# CARGO_TARGET_DIR).
ours=$(cargo metadata --format-version 1 --no-deps --manifest-path "$here/robots/Cargo.toml" |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')/release
# Timed rounds of each side, alternating. Each round runs a fresh copy of
# each side's program: the kernel gives a new file new pages, and where a
# call's code outgrows the L1 instruction cache (the G1's derivatives: 200
# KiB and more) its time depends on where those pages fall in the
# physically indexed caches: byte-identical copies of one binary time the
# G1's and the Go1's derivatives up to a fifth apart, each copy steady
# within itself. The median over fresh copies is the time a user's build
# can expect, where one copy's is a single draw.
ROUNDS=5
# `run_fresh PROGRAM ROUND ARGS…`: a fresh copy of PROGRAM run pinned with
# ARGS, then removed.
run_fresh() {
  local program=$1 round=$2 code=0
  shift 2
  local copy="$out/fresh-$(basename "$program")-$round"
  cp "$program" "$copy" || return 1
  "${pin[@]}" "$copy" "$@" || code=1
  rm -f "$copy"
  return $code
}
{
  "${pin[@]}" "$out/pinocchio" "$out/reference.txt" || status=1
  "${pin[@]}" "$out/mujoco" "$out/reference.txt" "$out/scratch.xml" || status=1
} > "$target/benchmarks/peers.json"
cat "$target/benchmarks/peers.json"
# The robots: ours writes the states and answers (checking them against each
# other), then alternating rounds of our times and Pinocchio's (which
# checks its answers against ours in every round before timing), both on
# the thread's CPU clock: one pass each, ours then Pinocchio's, once read
# the Panda 1.7× slower on our side than alone minutes later.
if [ "$robots_ok" = 1 ]; then
  robots=(cargo run --quiet --release --manifest-path "$here/robots/Cargo.toml" --bin constrained-robots --)
  {
    "${robots[@]}" write "$out/robots.txt" || status=1
    # Pinocchio generated through CasADi on the Panda, the UR5 and the G1
    # (benches/peers/casadi): generated from the file just written, so on
    # the same states; optional like the robots'.
    casadi=0
    casadi_generate "$out/robots.txt" "$out/casadi" >&2 && casadi=1 || status=1
    for round in $(seq "$ROUNDS"); do
      run_fresh "$ours/constrained-robots" "$round" time "$round" || status=1
      run_fresh "$out/robots" "$round" "$robot_data" "$out/robots.txt" "$round" || status=1
      if [ "$casadi" = 1 ]; then
        run_fresh "$out/casadi/casadi" "$round" "$out/casadi/casadi_states.txt" "$round" || status=1
      fi
    done
  } > "$target/benchmarks/robots.json"
  cat "$target/benchmarks/robots.json"
fi
# The kinematics: ours writes the states and answers (checking J q̇ against
# the frame's velocity, ∂q̈/∂τ against M⁻¹, A_G's linear rows against
# m J_c, Ȧ_G q̇ and ∂τ against differences), then alternating rounds as
# the robots' (Pinocchio checks every quantity against ours in
# every round before timing it).
if [ "$kinematics_ok" = 1 ]; then
  kinematics=(cargo run --quiet --release --manifest-path "$here/robots/Cargo.toml" --bin kinematics --)
  {
    "${kinematics[@]}" write "$out/kinematics.txt" || status=1
    for round in $(seq "$ROUNDS"); do
      run_fresh "$ours/kinematics" "$round" time "$round" || status=1
      run_fresh "$out/kinematics" "$round" "$robot_data" "$out/kinematics.txt" "$round" || status=1
    done
  } > "$target/benchmarks/kinematics.json"
  cat "$target/benchmarks/kinematics.json"
else
  status=1
fi
# The contacts: ours writes the states and answers (checking A q̈ = b), then
# alternating rounds of our times and Pinocchio's (which checks its
# answers against ours in every round before timing).
if [ "$contacts_ok" = 1 ]; then
  contacts=(cargo run --quiet --release --manifest-path "$here/robots/Cargo.toml" --bin contacts --)
  {
    "${contacts[@]}" write "$out/contacts.txt" || status=1
    for round in $(seq "$ROUNDS"); do
      run_fresh "$ours/contacts" "$round" time "$round" || status=1
      run_fresh "$out/contacts" "$round" "$out/contacts.txt" "$round" "$robot_data/go1_description/urdf/go1.urdf" \
        "$robot_data/g1_description/urdf/g1_29dof_rev_1_0.urdf" || status=1
    done
  } > "$target/benchmarks/contacts.json"
  cat "$target/benchmarks/contacts.json"
  # The instruction-cache report of the same systems (cachegrind).
  bash "$here/icache.sh" || status=1
  # The CPU time of building the standing G1's `acceleration`.
  bash "$here/build_time.sh" || status=1
else
  status=1
fi
exit $status
