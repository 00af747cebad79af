#!/usr/bin/env bash
# Runs every example at its default length and writes its plot into
# docs/plots, where the README shows them.
set -euo pipefail
cd "$(dirname "$0")/.."
for example in appell spherical_pendulum double_pendulum bead_on_hoop chaplygin_sleigh slider_crank two_link_arm crane spinning_top cart_pole_lqr panda quadruped quadruped_balance five_bar; do
    echo "== $example"
    cargo run --quiet --release --example "$example" -- --out docs/plots | grep -v "^  plot:" | tail -n 4
done
