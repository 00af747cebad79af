#!/usr/bin/env bash
# The peers' rows of BENCHMARKS.md: Pinocchio (C++) and MuJoCo (C), compiled
# against the headers and libraries of their Python wheels, on the same
# systems and states as the generated code. Each program checks its answer
# against the generated code's (chains/examples/peer_reference.rs) before it
# times anything, and exits with 1 if one disagrees.
#
# Sets up its own virtual environment (benches/peers/.venv); writes
# <target>/benchmarks/peers.json (one JSON object per line). Called by
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
if [ ! -x "$out/mujoco" ] || [ "$here/mujoco.c" -nt "$out/mujoco" ] || [ "$here/common.h" -nt "$out/mujoco" ]; then
  library=$(cd "$mujoco" && ls libmujoco.so.* | head -1)
  gcc -std=c11 -O3 -DNDEBUG -D_POSIX_C_SOURCE=200809L -I"$mujoco/include" "$here/mujoco.c" \
    -o "$out/mujoco" -L"$mujoco" -Wl,-rpath,"$mujoco" -l:"$library" -lm
fi

cargo run --quiet --release -p constrained-chains --example peer_reference -- "$out/reference.txt"
pin=()
if command -v taskset > /dev/null; then pin=(taskset -c 1); fi
status=0
{
  "${pin[@]}" "$out/pinocchio" "$out/reference.txt" || status=1
  "${pin[@]}" "$out/mujoco" "$out/reference.txt" "$out/scratch.xml" || status=1
} > "$target/benchmarks/peers.json"
cat "$target/benchmarks/peers.json"
exit $status
