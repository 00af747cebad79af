//! The size of the text `constrained_system!` writes for people and for
//! sympy (`DERIVATION` and `SYMBOLIC`), against the size of the input and of
//! the expression DAG, for the planar 32-link chain, a model with 520
//! definitions (`fixtures::definition_heavy`) and compositions nested as
//! text: the sizes the derivation-text check of docs/testing.md refers to.
//!
//! `cargo run --release -p constrained-codegen --example derivation_size`

use constrained_codegen::tools::fixtures::{definition_heavy, planar_chain};
use constrained_codegen::{analyse, emit, emit::derivation};

fn main() {
    // Compositions nested as text parse recursively: a large stack, as
    // rustc gives the macro.
    std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(table)
        .expect("thread")
        .join()
        .expect("the table");
}

fn table() {
    let nested = |depth: usize| {
        let e = format!("x{}", ".sin()".repeat(depth));
        format!(
            "struct Nested{depth} {{ coordinates: [x, y], mass: diag[1.0, 1.0], forces: [{e}, 0.0], constraints: [y == {e}] }}"
        )
    };
    println!("| model | input | DAG nodes | DERIVATION | SYMBOLIC | both / input |");
    println!("|---|---|---|---|---|---|");
    for (name, input) in [
        (
            "planar chain, 32 links".to_string(),
            planar_chain("Chain32", 32),
        ),
        (
            "520 definitions".to_string(),
            definition_heavy("Heavy", 520),
        ),
        (
            "1,040 definitions".to_string(),
            definition_heavy("Heavy", 1040),
        ),
        ("sin nested 10 deep, as text".to_string(), nested(10)),
        ("sin nested 20 deep, as text".to_string(), nested(20)),
        ("sin nested 50 deep, as text".to_string(), nested(50)),
        ("sin nested 100 deep, as text".to_string(), nested(100)),
    ] {
        let tokens = input.parse().expect("valid tokens");
        let equations = analyse(tokens).expect("expands");
        let text = derivation::text(&equations, &equations.partition);
        if let Some(dir) = std::env::args().nth(1) {
            let file = format!("{dir}/{}.txt", name.replace([' ', ','], "_"));
            std::fs::write(file, &text).expect("writable");
        }
        let symbolic = emit::symbolic_text_len(&equations);
        println!(
            "| {name} | {:.1} KB | {} | {:.1} KB | {:.1} KB | {:.1}× |",
            input.len() as f64 / 1024.0,
            equations.system.graph.len(),
            text.len() as f64 / 1024.0,
            symbolic as f64 / 1024.0,
            (text.len() + symbolic) as f64 / input.len() as f64,
        );
    }
}
