//! The expansion of the quadruped of `examples/support/quadruped.rs` (a
//! floating base, twelve joints, four feet fixed: 19 coordinates, 13 rows):
//! expansion time, lines and operations per `q̈`, with and without the
//! `jacobians` feature — the build cost of a legged robot.
//!
//! `cargo run --release -p constrained-codegen --example quadruped_size`
//! (with `QUADRUPED_DUMP=FILE`, the expansion without `jacobians` is
//! written there, pretty-printed)

use constrained_codegen::tools::op_count;
use constrained_codegen::{expand_with, Options};
use std::time::Instant;

fn main() {
    let inner =
        constrained_codegen::tools::fixtures::quadruped().expect("the workspace's quadruped");
    println!("| `jacobians` | expansion (s) | lines | operations per q̈ |");
    println!("|---|---|---|---|");
    let mut parts = [("", 0); 3];
    for jacobians in [true, false] {
        let tokens: proc_macro2::TokenStream = inner.parse().expect("the model is tokens");
        let started = Instant::now();
        let expanded = expand_with(tokens, Options { jacobians }).expect("the quadruped expands");
        let seconds = started.elapsed().as_secs_f64();
        let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
        let text = prettyplease::unparse(&file);
        let lines = text.lines().count();
        if let Ok(out) = std::env::var("QUADRUPED_DUMP") {
            std::fs::write(out, &text).expect("the dump is writable");
        }
        let ops = op_count::acceleration(&file).map_or(0, |o| o.total());
        println!("| {jacobians} | {seconds:.2} | {lines} | {ops} |");
        if !jacobians {
            parts = ["mass_matrix", "forces", "constraint_matrices"]
                .map(|name| (name, op_count::method(&file, name).map_or(0, |o| o.total())));
        }
    }
    println!("\nOperations of the parts, each alone (shared work counted in each):");
    for (name, ops) in parts {
        println!("- `{name}`: {ops}");
    }
}
