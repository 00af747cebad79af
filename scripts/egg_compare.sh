#!/usr/bin/env bash
# Issue 15's measurement of an e-graph (egg) against the rule-based
# factoring of constrained-codegen, on every reference model: the table of
# BENCHMARKS.md's "Factoring: rules against an e-graph". benches/egg is a
# crate of its own, outside the workspace, so that the test command never
# compiles egg.
set -euo pipefail
cd "$(dirname "$0")/../benches/egg"
pin=()
if command -v taskset > /dev/null; then pin=(taskset -c 1); fi
cargo build --release --quiet
"${pin[@]}" cargo run --release --quiet
