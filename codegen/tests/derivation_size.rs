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
    let equations = analyse(input.parse().expect("tokens")).expect("expands");
    let text = derivation::text(&equations, &equations.partition).len()
        + emit::symbolic_text_len(&equations);
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

/// The part of a robot's derivation between `from` and `to`.
fn part<'a>(text: &'a str, from: &str, to: &str) -> &'a str {
    let start = text.find(from).expect("the part is there");
    let end = text[start..].find(to).map_or(text.len(), |e| start + e);
    &text[start..end]
}

/// A robot's derivation has a part per body — its joint, placement,
/// inertia and the recursions' named intermediates, `v₂.ωx`, `f₂.nz`,
/// `Iᶜ₂.m` — and that part grows linearly with the bodies: its bytes per
/// body level off (within 1.25× from 4 to 7 joints of the Panda; the
/// 2-joint prefix's, with less below each body, are shorter). The 2-joint
/// prefix's derivation is pinned as a snapshot.
#[test]
fn a_robots_derivation_has_a_part_per_body_growing_linearly() {
    use constrained_codegen::tools::fixtures::panda;
    let text = |joints: usize| {
        let source = panda(&format!("Panda{joints}"), joints);
        let equations = analyse(source.parse().expect("tokens")).expect("the Panda expands");
        derivation::text(&equations, &equations.partition)
    };
    let mut per_body = Vec::new();
    for joints in [2, 4, 7] {
        let full = text(joints);
        let bodies = part(&full, "Bodies (", "Mass matrix");
        for k in 1..=joints {
            assert!(
                bodies.contains(&format!("  Body {k} `link{k}`")),
                "{bodies}"
            );
        }
        assert!(bodies.contains(&format!(
            "f{}.n",
            constrained_codegen::expr::print::subscript(joints)
        )));
        let mass = part(&full, "Mass matrix", "Impressed forces");
        println!(
            "Panda, {joints} joints: derivation {} bytes, bodies {} ({} per body), M {} bytes",
            full.len(),
            bodies.len(),
            bodies.len() / joints,
            mass.len()
        );
        per_body.push(bodies.len() as f64 / joints as f64);
    }
    // The first bodies' forces are the shortest (fewer bodies below
    // them); from 4 to 7 joints the bytes per body level off.
    let growth = per_body[2] / per_body[1];
    assert!(
        growth < 1.25,
        "bytes per body grew {growth:.2}× from 4 to 7: {per_body:?}"
    );
    assert!(per_body[2] / per_body[0] < 2.0, "{per_body:?}");
    insta::assert_snapshot!("panda2_derivation", text(2));
}
