#!/usr/bin/env bash
# The instruction-cache report of the Contacts section: for each contact
# system's `acceleration` and `acceleration_and_multipliers` (and the
# Go1's `acceleration_and_multiplier_jacobians`), each fixed-base robot's
# `acceleration`, `mass_matrix` and `inverse_dynamics`, and the
# Kinematics table's derivatives and centroidal map,
# the instructions a call runs, the distinct 64-byte lines of code it runs
# (its hot path's size) and its L1 instruction-cache misses per call, under
# cachegrind with this machine's own L1i geometry (read from sysfs).
#
# Each figure is a difference of two runs of `contacts spin SYSTEM WHAT
# PASSES` (or `constrained-robots`' or `kinematics`' `spin ROBOT WHAT
# PASSES`), which make the
# states and then only calls: PASSES = 0 (the set-up alone) against
# PASSES = 50 (1,000 calls) for instructions and misses; against PASSES = 1
# with a 1 MiB L1i, where only first touches miss, for the lines (lines the
# set-up also ran are not counted, so this is a lower bound). Writes
# <target>/benchmarks/icache.json (one JSON object per line). Called by
# benches/peers/run.sh after the contacts' rounds; needs valgrind
# (skipped, with a note, without it).
set -euo pipefail
cd "$(dirname "$0")/../.."
target=$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
# The robots' crate is outside the workspace: run.sh's `cargo run
# --manifest-path` builds it into its own target directory, the workspace's
# only where CARGO_TARGET_DIR is set.
bins=$(cargo metadata --format-version 1 --no-deps --manifest-path benches/peers/robots/Cargo.toml |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
contacts=$bins/release/contacts
robots=$bins/release/constrained-robots
kinematics=$bins/release/kinematics
out=$target/benchmarks/icache.json
if ! command -v valgrind > /dev/null; then
  echo "   no valgrind: no instruction-cache report" >&2
  rm -f "$out"
  exit 0
fi
# The first level-1 instruction cache's size, ways and line (sysfs).
geometry=""
for index in /sys/devices/system/cpu/cpu0/cache/index*; do
  if [ "$(cat "$index/level")" = 1 ] && [ "$(cat "$index/type")" = Instruction ]; then
    size=$(cat "$index/size"); size=${size%K}
    geometry="$((size * 1024)),$(cat "$index/ways_of_associativity"),$(cat "$index/coherency_line_size")"
  fi
done
[ -n "$geometry" ] || geometry="32768,8,64"
# Ir (instructions) and I1 misses of one run of BINARY, as "IR MISSES".
counts() {
  local i1=$1 binary=$2 system=$3 what=$4 passes=$5 file
  file=$(mktemp)
  valgrind --tool=cachegrind --cache-sim=yes --I1="$i1" --D1=32768,8,64 --LL=33554432,16,64 \
    --cachegrind-out-file="$file" "$binary" spin "$system" "$what" "$passes" > /dev/null 2>&1
  awk '/^summary:/ { print $2, $3 }' "$file"
  rm -f "$file"
}
calls=1000
mkdir -p "$(dirname "$out")"
: > "$out"
cases=()
for system in quadruped go1 five_bar g1_points g1_flat; do
  for what in acceleration acceleration_and_multipliers; do cases+=("$contacts $system $what"); done
done
cases+=("$contacts go1 jacobians")
for robot in panda ur5 talos xarm7 kinova g1_arms_locked g1; do
  for what in acceleration mass_matrix inverse_dynamics; do cases+=("$robots $robot $what"); done
done
for robot in panda g1 go1; do
  for what in inverse_dynamics_jacobian acceleration_jacobian centroidal_map; do
    cases+=("$kinematics $robot $what")
  done
done
for case in "${cases[@]}"; do
    read -r binary system what <<< "$case"
    read -r ir0 miss0 < <(counts "$geometry" "$binary" "$system" "$what" 0)
    read -r ir1 miss1 < <(counts "$geometry" "$binary" "$system" "$what" 50)
    read -r _ cold0 < <(counts 1048576,16,64 "$binary" "$system" "$what" 0)
    read -r _ cold1 < <(counts 1048576,16,64 "$binary" "$system" "$what" 1)
    python3 - "$(basename "$binary")" "$system" "$what" "$geometry" "$calls" "$ir0" "$ir1" "$miss0" "$miss1" "$cold0" "$cold1" >> "$out" <<'PY'
import json, sys
binary, system, what, geometry, calls = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5])
ir0, ir1, miss0, miss1, cold0, cold1 = map(int, sys.argv[6:])
size, ways, line = map(int, geometry.split(","))
print(json.dumps({"binary": binary, "system": system, "what": what, "instructions": (ir1 - ir0) / calls,
                  "i1_misses": (miss1 - miss0) / calls, "lines": cold1 - cold0, "line": line,
                  "i1_bytes": size, "i1_ways": ways}))
PY
done
cat "$out"
