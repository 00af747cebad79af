#!/usr/bin/env bash
# The build-time rows of BENCHMARKS.md: the CPU time of building a binary
# that calls the standing G1's `acceleration` (the Unitree G1 from
# example-robot-data's URDF on three points of each foot, the invocation
# benches/peers/robots/build.rs writes), its dependencies already built: a
# crate of its own under <target>/build-time, its main file touched and
# rebuilt three times, in two release profiles: with the generator built
# at opt-level 3 as docs/dsl.md advises for large models ("advised"), and
# cargo's default, which builds proc macros unoptimized ("default"). Writes
# <target>/benchmarks/build_time.json (one JSON object per build: user,
# system and wall seconds of cargo and its children). Called by run.sh
# after the robots' crate is built (EXAMPLE_ROBOT_DATA set).
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
here=benches/peers
target=$(cargo metadata --format-version 1 --no-deps |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
# Where the robots' build script wrote the invocation (its OUT_DIR).
out_dir=$(cargo build --quiet --release --message-format=json --manifest-path "$here/robots/Cargo.toml" |
    python3 -c '
import json, sys
dirs = [m["out_dir"] for m in map(json.loads, sys.stdin)
        if m.get("reason") == "build-script-executed" and "constrained-robots" in m["package_id"]]
print(dirs[-1] if dirs else "")')
if [ ! -f "$out_dir/g1_standing.rs" ]; then
  echo "build_time: no g1_standing.rs from the robots' build script" >&2
  exit 1
fi
for profile in advised default; do
crate=$target/build-time/g1_standing_$profile
mkdir -p "$crate/src"
cat > "$crate/Cargo.toml" <<TOML
[package]
name = "g1-standing-build"
version = "0.1.0"
edition = "2021"
publish = false

[workspace]

[dependencies]
constrained = { path = "$repo" }
TOML
if [ "$profile" = advised ]; then
  cat >> "$crate/Cargo.toml" <<TOML

[profile.release.package.constrained-codegen]
opt-level = 3
[profile.release.package.constrained-macros]
opt-level = 3
TOML
fi
# The system as written without the peers' `dispatch: [avx]` (build.rs's
# DISPATCH), whose copies would compile the large methods twice.
grep -v '^ *dispatch: \[avx\],$' "$out_dir/g1_standing.rs" > "$crate/src/g1_standing.rs"
if grep -q 'dispatch:' "$crate/src/g1_standing.rs"; then
  echo "build_time: the dispatch line of g1_standing.rs was not removed" >&2
  exit 1
fi
cat > "$crate/src/main.rs" <<RUST
// The included file's own constants are not all read here.
#![allow(dead_code)]
include!("g1_standing.rs");

fn main() {
    use constrained::ConstrainedSystem;
    let s = G1Standing::<f64>::new(
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    );
    let mut q = constrained::nalgebra::SVector::<f64, 36>::zeros();
    q[3] = 1.0;
    let state = constrained::State::new(0.0, q, constrained::nalgebra::SVector::zeros());
    println!("{:?}", ConstrainedSystem::acceleration(&s, &state).map(|a| a[0]).ok());
}
RUST
CARGO_TARGET_DIR=$target/build-time/target-$profile cargo build --quiet --release --manifest-path "$crate/Cargo.toml"
CARGO_TARGET_DIR=$target/build-time/target-$profile python3 - "$crate" "$profile" <<'PY'
import json, os, resource, subprocess, sys, time
crate, profile = sys.argv[1], sys.argv[2]
for build in range(1, 4):
    os.utime(os.path.join(crate, "src", "main.rs"))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    subprocess.run(["cargo", "build", "--quiet", "--release", "--manifest-path",
                    os.path.join(crate, "Cargo.toml")], check=True)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(json.dumps({"system": "g1_standing", "what": "acceleration", "profile": profile, "build": build,
                      "user": round(after.ru_utime - before.ru_utime, 3),
                      "sys": round(after.ru_stime - before.ru_stime, 3),
                      "wall": round(wall, 3)}))
PY
done > "$target/benchmarks/build_time.json"
cat "$target/benchmarks/build_time.json"
