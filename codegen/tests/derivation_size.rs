//! The derivation's text (`DERIVATION`) and the sympy export (`SYMBOLIC`)
//! grow linearly with the expression DAG, not with the expanded tree:
//! definitions stay named, shared subexpressions are written once, long
//! sparse rows list their nonzeros. Doubling an input must at most double
//! the text (2.3× allows for the fixed part); printing the tree instead
//! gives 4× per doubling on nested compositions.

use constrained_codegen::tools::fixtures::definition_heavy;
use constrained_codegen::{analyse, emit, emit::derivation};

/// (DAG nodes, bytes of DERIVATION + SYMBOLIC) of one model.
fn sizes(input: &str) -> (usize, usize) {
    let (equations, partition) = analyse(input.parse().expect("tokens")).expect("expands");
    let text = derivation::text(&equations, &partition).len() + emit::symbolic_text_len(&equations);
    (equations.system.graph.len(), text)
}

fn nested(depth: usize) -> String {
    let e = format!("x{}", ".sin()".repeat(depth));
    format!(
        "struct Nested {{ coordinates: [x, y], mass: diag[1.0, 1.0], forces: [{e}, 0.0], constraints: [y == {e}] }}"
    )
}

/// Doubling the input at most doubles the text, and the text per unit of
/// `measure` (DAG nodes, or input bytes) stays within 25 %.
fn assert_linear(name: &str, unit: &str, inputs: &[String], by_input: bool) {
    let measured: Vec<(usize, usize)> = inputs
        .iter()
        .map(|i| {
            let (nodes, text) = sizes(i);
            (if by_input { i.len() } else { nodes }, text)
        })
        .collect();
    for pair in measured.windows(2) {
        let ((n0, t0), (n1, t1)) = (pair[0], pair[1]);
        let text = t1 as f64 / t0 as f64;
        let per_unit = (t1 as f64 / n1 as f64) / (t0 as f64 / n0 as f64);
        println!(
            "{name}: {n0} → {n1} {unit}, {t0} → {t1} bytes ({text:.2}×; per {unit} {per_unit:.2}×)"
        );
        assert!(
            text < 2.3,
            "{name}: the text grew {text:.2}× when the input doubled"
        );
        assert!(
            per_unit < 1.25,
            "{name}: bytes per {unit} grew {per_unit:.2}×"
        );
    }
}

#[test]
fn text_grows_linearly_with_nested_compositions() {
    // Nested as text, parsed recursively: rustc's stack, not the test's.
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(|| {
            assert_linear(
                "sin∘…∘sin",
                "node",
                &[nested(25), nested(50), nested(100)],
                false,
            )
        })
        .expect("thread")
        .join()
        .expect("linear");
}

#[test]
fn text_grows_linearly_with_the_number_of_definitions() {
    let inputs: Vec<String> = [130, 260, 520]
        .iter()
        .map(|&n| definition_heavy("Heavy", n))
        .collect();
    // The DAG of this family is not monotonic in the definitions (which of
    // them the constraints reach changes): measured against the input.
    assert_linear("definitions", "input byte", &inputs, true);
}
