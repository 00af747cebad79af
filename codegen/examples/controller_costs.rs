//! What the controller's methods cost on the Franka Panda written as
//! bodies (`fixtures::panda`): the expansion time and lines with and
//! without the `jacobians` feature, a `frames` section and a
//! `derivatives` section, and the
//! operations of each kinematics method, of inverse dynamics and of its
//! derivatives (`op_count::method` on the expansion).
//!
//! `cargo run --release -p constrained-codegen --example controller_costs`

use constrained_codegen::tools::fixtures::panda;
use constrained_codegen::{expand_with, tools::op_count, Options};
use std::time::Instant;

/// The methods counted, where the expansion has them.
const METHODS: &[&str] = &[
    "inverse_dynamics",
    "inverse_dynamics_jacobian",
    "mass_matrix",
    "tool_jacobian",
    "tool_acceleration_bias",
    "center_of_mass",
    "center_of_mass_jacobian",
    "center_of_mass_velocity",
    "centroidal_map",
    "centroidal_map_bias",
];

/// The expansion of `source`: the fastest of three timings, and the file.
fn expand_timed(source: &str, options: Options) -> (f64, syn::File) {
    let mut best = f64::INFINITY;
    let mut file = None;
    for _ in 0..3 {
        let tokens: proc_macro2::TokenStream = source.parse().expect("the fixture is tokens");
        let start = Instant::now();
        let expanded = expand_with(tokens, options).expect("the Panda expands");
        best = best.min(start.elapsed().as_secs_f64());
        file = Some(syn::parse2(expanded).expect("the expansion is Rust"));
    }
    (best, file.expect("three expansions"))
}

fn main() {
    let plain = panda("Panda", 7);
    let framed = plain.replace(
        "        forces: [",
        "        frames: [tool { body: link7, xyz: [0.0, 0.0, 0.107] }],\n        forces: [",
    );
    let derived = plain.replace(
        "        forces: [",
        "        derivatives: [inverse_dynamics],\n        forces: [",
    );
    let both = framed.replace(
        "        forces: [",
        "        derivatives: [inverse_dynamics],\n        forces: [",
    );
    println!("| Panda with | `jacobians` | expansion (s) | lines |");
    println!("|---|---|---|---|");
    let mut counted = None;
    let sources = [
        ("neither", &plain),
        ("frames: [tool]", &framed),
        ("derivatives: [inverse_dynamics]", &derived),
        ("both", &both),
    ];
    for (name, source) in sources {
        for jacobians in [false, true] {
            let (seconds, file) = expand_timed(source, Options { jacobians });
            let lines = prettyplease::unparse(&file).lines().count();
            println!("| {name} | {jacobians} | {seconds:.3} | {lines} |");
            counted = Some(file);
        }
    }
    let file = counted.expect("eight expansions");
    println!("\n| method | operations |\n|---|---|");
    for m in METHODS {
        if let Some(ops) = op_count::method(&file, m) {
            println!(
                "| `{m}` | {} ({} mul, {} add, {} sub, {} div, {} neg, {} functions) |",
                ops.total(),
                ops.mul,
                ops.add,
                ops.sub,
                ops.div,
                ops.neg,
                ops.functions
            );
        }
    }
    if let Some(ops) = op_count::acceleration(&file) {
        println!("| `acceleration` | {} |", ops.total());
    }
}
