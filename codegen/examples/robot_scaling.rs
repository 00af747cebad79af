//! Operations per `q̈` and expansion time of the Franka Panda's 1…7-joint
//! prefixes written as bodies (`fixtures::panda`): the table of the DSL
//! guide's rigid-body section, docs/dsl.md (`M` by the composite-rigid-body
//! algorithm, the bias forces by recursive Newton–Euler, then the library's
//! solve).
//!
//! `cargo run --release -p constrained-codegen --example robot_scaling`

use constrained_codegen::tools::fixtures::panda;
use constrained_codegen::{expand, expand_with, tools::op_count, Options};
use std::time::Instant;

fn main() {
    println!(
        "| joints | operations per q̈ | inverse dynamics | expansion (s) | lines | without `jacobians`: expansion (s) | lines |"
    );
    println!("|---|---|---|---|---|---|---|");
    for joints in 1..=7 {
        let source = panda(&format!("Panda{joints}"), joints);
        let tokens: proc_macro2::TokenStream = source.parse().expect("the fixture is tokens");
        let start = Instant::now();
        let expanded = expand(tokens).expect("the Panda expands");
        let seconds = start.elapsed().as_secs_f64();
        let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
        let text = prettyplease::unparse(&file);
        let lines = text.lines().count();
        if std::env::var("ROBOT_SCALING_DUMP").is_ok_and(|j| j == joints.to_string()) {
            std::fs::write(format!("/tmp/panda{joints}.rs"), &text).expect("writable");
        }
        let ops = op_count::acceleration(&file).map_or(0, |o| o.total());
        let inverse = op_count::method(&file, "inverse_dynamics").map_or(0, |o| o.total());
        let lean = Options { jacobians: false };
        let tokens: proc_macro2::TokenStream = source.parse().expect("the fixture is tokens");
        let start = Instant::now();
        let expanded = expand_with(tokens, lean).expect("the Panda expands");
        let lean_seconds = start.elapsed().as_secs_f64();
        let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
        let lean_lines = prettyplease::unparse(&file).lines().count();
        println!(
            "| {joints} | {ops} | {inverse} | {seconds:.3} | {lines} | {lean_seconds:.3} | {lean_lines} |"
        );
    }
}
