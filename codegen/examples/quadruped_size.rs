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
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/support/quadruped.rs"
    );
    // The file writes the system once inside a `macro_rules!` (for the
    // tests' twin with a fifth row): this is the example's instance.
    let text = std::fs::read_to_string(path)
        .expect("the model is readable")
        .replace("$(#[$attr])*", "")
        .replace("$($extra)*", "")
        .replace("$name", "Quadruped");
    let start = text.find("constrained_system! {").expect("a system") + "constrained_system!".len();
    let body = &text[start..];
    let (mut depth, mut end) = (0usize, 0usize);
    for (i, c) in body.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    end = i;
                    break;
                }
            }
            _ => {}
        }
    }
    let inner = &body[body.find('{').expect("a brace") + 1..end];
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
