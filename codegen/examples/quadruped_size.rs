//! The expansion of the quadruped of `examples/support/quadruped.rs` (a
//! floating base, twelve joints, four feet fixed: 19 coordinates, 13 rows):
//! expansion time, lines and operations per `q̈`, with and without the
//! `jacobians` feature — the build cost of a legged robot.
//!
//! `cargo run --release -p constrained-codegen --example quadruped_size`

use constrained_codegen::tools::op_count;
use constrained_codegen::{expand_with, Options};
use std::time::Instant;

fn main() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/support/quadruped.rs"
    );
    let text = std::fs::read_to_string(path).expect("the model is readable");
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
    for jacobians in [true, false] {
        let tokens: proc_macro2::TokenStream = inner.parse().expect("the model is tokens");
        let started = Instant::now();
        let expanded = expand_with(tokens, Options { jacobians }).expect("the quadruped expands");
        let seconds = started.elapsed().as_secs_f64();
        let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
        let lines = prettyplease::unparse(&file).lines().count();
        let ops = op_count::acceleration(&file).map_or(0, |o| o.total());
        println!("| {jacobians} | {seconds:.2} | {lines} | {ops} |");
    }
}
