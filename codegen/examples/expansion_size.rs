//! The size of the code `constrained_system!` generates for the planar
//! N-link chain, as lines and bytes of the formatted expansion, and the
//! lines of the acceleration solver (`fn gauss`) alone, written as JSON for
//! the benchmark report. The whole expansion grows quadratically because
//! `mass_matrix`, `constraint_matrices` and `SYMBOLIC` are dense n × n and
//! k × n; the solver grows linearly.
//!
//! `cargo run -p constrained-codegen --example expansion_size -- target/benchmarks/expansion.json`

use constrained_codegen::{expand, tools::fixtures::planar_chain};

fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        // Under cargo's target directory (CARGO_TARGET_DIR when set).
        let target = std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into());
        format!("{target}/benchmarks/expansion.json")
    });
    let mut rows = Vec::new();
    for links in [1usize, 2, 4, 8, 16, 32] {
        let tokens = planar_chain("Chain", links).parse().expect("valid tokens");
        let file: syn::File = syn::parse2(expand(tokens).expect("expands")).expect("valid Rust");
        let text = prettyplease::unparse(&file);
        let solver = solver_lines(&text);
        rows.push(format!(
            "{{\"links\": {links}, \"lines\": {}, \"bytes\": {}, \"solver_lines\": {solver}}}",
            text.lines().count(),
            text.len()
        ));
        println!(
            "N = {links:>2}: {} lines, {} bytes; solver {solver} lines",
            text.lines().count(),
            text.len()
        );
    }
    if let Some(dir) = std::path::Path::new(&path).parent() {
        std::fs::create_dir_all(dir).expect("output folder");
    }
    std::fs::write(&path, format!("[{}]\n", rows.join(", "))).expect("writable");
}

/// Lines from `fn gauss(` to the next item at the same indentation.
fn solver_lines(text: &str) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    let Some(start) = lines
        .iter()
        .position(|l| l.trim_start().starts_with("fn gauss("))
    else {
        return 0;
    };
    let indent = lines[start].len() - lines[start].trim_start().len();
    let end = lines[start + 1..]
        .iter()
        .position(|l| l.len() - l.trim_start().len() == indent && l.trim_start() == "}")
        .map_or(lines.len(), |i| start + 1 + i + 1);
    end - start
}
