#!/usr/bin/env bash
# Runs every test of the project: unit, integration, property, snapshot,
# compile-fail (trybuild) and doc tests; the benches once each in test mode
# so that they cannot rot; the main example; and the embedded run (firmware
# on an emulated Cortex-M4F under QEMU, compared with the host). Needs cargo;
# installs the thumbv7em target and QEMU (Debian package) when missing.
set -euo pipefail
cd "$(dirname "$0")/.."

export INSTA_UPDATE=no # snapshots are compared, never written, here
cargo test --workspace --all-targets
cargo test --workspace --doc
# The main example checks itself and exits non-zero on disagreement.
cargo run --quiet --example appell > /dev/null
bash scripts/embedded.sh
