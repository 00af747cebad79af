//! Writes one `constrained_system!` invocation per chain length: the macro
//! cannot loop over N, and the DSL text comes from one generator
//! (`constrained_codegen::tools::fixtures::planar_chain`, and `joint_angle_pendulum`
//! for the same pendulums in joint angles) shared with the benches.

use std::fmt::Write;

fn main() {
    let mut out = String::new();
    for links in constrained_chains_lengths() {
        let source =
            constrained_codegen::tools::fixtures::planar_chain(&format!("Chain{links}"), links);
        let _ = writeln!(out, "constrained::constrained_system! {{\n{source}\n}}\n");
    }
    for links in constrained_pendulum_lengths() {
        let source = constrained_codegen::tools::fixtures::joint_angle_pendulum(
            &format!("PendulumAngles{links}"),
            links,
        );
        let _ = writeln!(out, "constrained::constrained_system! {{\n{source}\n}}\n");
    }
    // The Franka Panda from published parameters, as bodies.
    let panda = constrained_codegen::tools::fixtures::panda("Panda", 7);
    let _ = writeln!(out, "constrained::constrained_system! {{\n{panda}\n}}\n");
    let path = std::path::Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
        .join("chains.rs");
    std::fs::write(path, out).expect("OUT_DIR is writable");
    println!("cargo::rerun-if-changed=build.rs");
}

/// The lengths generated (the structs `Chain1`, `Chain2`, … that `src/lib.rs`
/// includes); keep in step with the list in its docs.
fn constrained_chains_lengths() -> [usize; 9] {
    [1, 2, 3, 4, 8, 12, 16, 24, 32]
}

/// The joint-angle pendulums generated (`PendulumAngles2`, …): dense `M(q)`
/// from energies. Keep in step with the docs of `src/lib.rs`.
fn constrained_pendulum_lengths() -> [usize; 3] {
    [2, 4, 8]
}
