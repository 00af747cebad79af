# Sourced by scripts/benchmarks.sh and scripts/compare_acceleration.sh: the
# one definition of how benchmark binaries are built. Every function and
# loop starts on a 64-byte boundary, in a target directory of their own
# (<target>/aligned, the target directory being CARGO_TARGET_DIR when set), so that a ratio of two small functions does not depend
# on where the linker happened to place them: the same Appell comparison,
# unchanged, read 0.82× in one build and 1.50× in the next (eq. 32 by hand
# alone moved from 3.3 to 5.8 ns per call); aligned, eq. 32 by hand,
# unchanged in three builds that differed elsewhere, measured 38.0-38.5 ns
# (12 states) and 20.6-21.0 µs (1024 states).
ALIGNED_RUSTFLAGS="-C llvm-args=-align-all-functions=6 -C llvm-args=-align-loops=64"
ALIGNED_TARGET_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')/aligned"
