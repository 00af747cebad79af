//! The operations of every reference model's generated `acceleration`
//! (`op_count::acceleration` on the expansion), as JSON for the sympy suite,
//! which counts sympy's `cse` of the same `q̈` beside it
//! (tests/sympy/test_op_counts.py) for the table of BENCHMARKS.md.
//!
//! `cargo run -p constrained-codegen --example op_counts -- target/sympy/op_counts.json`

#[path = "../tests/common/mod.rs"]
mod common;

use constrained_codegen::{expand, tools::op_count};
use std::fmt::Write;

fn main() {
    let out = std::env::args().nth(1).unwrap_or_else(|| {
        // Under cargo's target directory (CARGO_TARGET_DIR when set).
        let target = std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into());
        format!("{target}/sympy/op_counts.json")
    });
    let mut json = String::from("{\n");
    let models = common::model_invocations();
    for (i, model) in models.iter().enumerate() {
        let expanded = expand(model.tokens.clone()).expect("every model expands");
        let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
        // Every reference model has a straight-line solve: a count the
        // counter refuses (a construct it does not know) is a failure here,
        // not a model the sympy comparison would silently skip.
        let Some(ops) = op_count::acceleration(&file) else {
            panic!("op_count refuses {}'s acceleration", model.name);
        };
        let counted = format!(
            "{{\"add\": {}, \"sub\": {}, \"mul\": {}, \"div\": {}, \"neg\": {}, \"functions\": {}, \"total\": {}}}",
            ops.add, ops.sub, ops.mul, ops.div, ops.neg, ops.functions, ops.total()
        );
        let comma = if i + 1 < models.len() { "," } else { "" };
        let _ = writeln!(json, "  \"{}\": {counted}{comma}", model.name);
    }
    json.push_str("}\n");
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).expect("output directory");
    }
    std::fs::write(&out, json).expect("writable output");
    println!("{out}");
}
