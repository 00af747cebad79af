#!/usr/bin/env bash
# The URDF sweep: every URDF file of the example-robot-data wheel that
# Pinocchio loads, read by `constrained` as written (fixed base), compared
# with Pinocchio's aba, crba, rnea and generalized gravity by coordinate
# name (benches/urdf_sweep.py says how). Not part of the test command: it
# uses the peers' virtual environment (benches/peers/.venv, set up here as
# benches/peers/run.sh does) and builds a crate per robot. Writes
# <target>/benchmarks/urdf_sweep.json and prints the table for BENCHMARKS.md;
# then benches/growth.py counts the G1's truncations (growth.json) and
# rewrites BENCHMARKS.md's Growth section.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
here=benches/peers
target=$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
site=$("$here/.venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
robots="$site/cmeel.prefix/share/example-robot-data/robots"
# The expansion tool, in release mode (the macro's own work, timed per file).
CARGO_TARGET_DIR="$target/urdf-sweep/tool" cargo build --quiet --release \
    --manifest-path benches/urdf_sweep/Cargo.toml
"$here/.venv/bin/python" benches/urdf_sweep.py "$robots" "$target" "$repo"
# The G1's truncations: operations per q̈ against the joints' count.
"$here/.venv/bin/python" benches/growth.py "$robots" "$target" "$repo"
