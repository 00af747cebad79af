//! Hostile and unusual input: the macro never panics, and what it accepts
//! compiles (a spanned error otherwise). Each test is named after what it
//! guards (issue 13's findings).

use constrained_codegen::expand;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Expands `body` (the inside of `constrained_system! { .. }`), failing the
/// test on a panic; the error text, if any.
fn outcome(body: &str) -> Result<String, String> {
    let tokens: proc_macro2::TokenStream = body.parse().expect("tokens");
    match catch_unwind(AssertUnwindSafe(|| expand(tokens))) {
        Ok(Ok(code)) => Ok(code.to_string()),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => panic!("the macro panicked on:\n{body}"),
    }
}

fn rejected(body: &str, why: &str) {
    match outcome(body) {
        Err(e) => assert!(
            e.contains(why),
            "expected an error about {why:?}, got {e:?}"
        ),
        Ok(_) => panic!("accepted:\n{body}"),
    }
}

#[test]
fn raw_identifiers_are_rejected_not_a_panic() {
    rejected(
        "struct S { coordinates: [r#type], mass: diag[1.0] }",
        "raw identifier",
    );
    rejected(
        "struct S { coordinates: [x], parameters: [r#t], mass: diag[1.0], forces: [r#t] }",
        "raw identifier",
    );
}

#[test]
fn non_finite_constants_are_errors_not_a_panic() {
    rejected(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [1e309] }",
        "finite",
    );
    rejected(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [1e308 * 1e308] }",
        "finite",
    );
}

/// `x·1e155` in a constraint puts `1e310` into `A M⁻¹ Aᵀ`: ∞ in f64 at run
/// time too, which would drop the constraint silently. A compile error
/// that says so, not a panic; `1e150` still expands.
#[test]
fn coefficients_whose_products_overflow_are_reported() {
    rejected(
        "struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [x * 1e155 + y == 1.0] }",
        "overflows f64",
    );
    let ok = outcome(
        "struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [x * 1e150 + y == 1.0] }",
    );
    assert!(ok.is_ok(), "{ok:?}");
}

/// −2⁶³ · 2⁶⁴ overflows i128 arithmetic in exact folding but not f64: the
/// product must come out as −2¹²⁷, not a panic or a wrapped value.
#[test]
fn integer_overflow_in_constant_folding_is_not_a_panic() {
    match outcome(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [-9223372036854775808 * 18446744073709551616 * x] }",
    ) {
        Ok(code) => assert!(
            code.contains("[[- :: constrained :: __private :: lit :: < T > (170141183460469230000000000000000000000f64) * x]]"),
            "−2¹²⁷·x expected in {code}"
        ),
        Err(e) => assert!(e.contains("overflow"), "an error must say why: {e}"),
    }
}

#[test]
fn integer_powers_beyond_i32_are_rejected() {
    rejected(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [x.powi(4294967298)] }",
        "powi",
    );
}

/// 2^4294967295 and 1.5^3e9 overflow f64: errors, never the 0.5 and 0
/// that wrapping exponents once folded them to.
#[test]
fn constant_powers_that_overflow_are_rejected_not_folded_wrongly() {
    for body in [
        "struct S { coordinates: [x], mass: diag[1.0], forces: [2.0.powi(4294967295) * x] }",
        "struct S { coordinates: [x], mass: diag[1.0], forces: [1.5.powi(3000000000) * x] }",
    ] {
        rejected(body, "powi");
    }
    // In range, a constant power folds to its exact value.
    let code =
        outcome("struct S { coordinates: [x], mass: diag[1.0], forces: [2.0.powi(10) * x] }")
            .expect("accepted");
    assert!(code.contains("1024f64"), "2^10 folded to 1024: {code}");
}

#[test]
fn names_that_collide_with_generated_code_are_rejected() {
    for name in [
        "correction",
        "None",
        "Some",
        "Ok",
        "Err",
        "Result",
        "Option",
    ] {
        rejected(
            &format!("struct S {{ coordinates: [x], parameters: [{name}], mass: diag[1.0] }}"),
            "reserved",
        );
    }
    rejected("struct T { coordinates: [x], mass: diag[1.0] }", "reserved");
}

#[test]
fn forwarded_derives_that_conflict_are_rejected() {
    for derive in ["Debug", "Clone", "Default", "Copy", "PartialEq"] {
        let body = format!("#[derive({derive})] struct S {{ coordinates: [x], mass: diag[1.0] }}");
        rejected(&body, "derive");
    }
}

#[test]
fn cfg_on_the_struct_is_rejected() {
    rejected(
        "#[cfg(test)] struct S { coordinates: [x], mass: diag[1.0] }",
        "cfg",
    );
}

/// Stack-hungry input (rustc runs the macro on an 8 MiB stack): deep
/// nesting is a spanned error, not a crash of the compiler.
fn expand_on_rustc_stack(body: String) -> Result<String, String> {
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || outcome(&body))
        .expect("thread")
        .join()
        .expect("no panic")
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    for expression in [
        format!("{}x{}", "(".repeat(1000), ")".repeat(1000)),
        format!("{}x", "-".repeat(20_000)),
        format!("x{}", ".sin()".repeat(20_000)),
        vec!["x"; 20_000].join(" * "),
    ] {
        let body =
            format!("struct S {{ coordinates: [x], mass: diag[1.0], forces: [{expression}] }}");
        match expand_on_rustc_stack(body) {
            Err(e) => assert!(e.contains("nests more than"), "{e}"),
            Ok(_) => panic!("accepted"),
        }
    }
    // Within the bound, the same shapes expand.
    let body = format!(
        "struct S {{ coordinates: [x], mass: diag[1.0], forces: [{}x{} + x{}] }}",
        "(".repeat(100),
        ")".repeat(100),
        ".sin()".repeat(100)
    );
    assert!(expand_on_rustc_stack(body).is_ok());
}

/// Runs `body` with a watchdog: a regression to exponential time fails the
/// test instead of hanging the suite. The bound is ~1000× the expected time.
fn finishes(body: String) -> Result<String, String> {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || send.send(outcome(&body)))
        .expect("thread");
    receive
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("expansion did not finish in 60 s")
}

/// `dᵢ = dᵢ₋₁·dᵢ₋₁ + x`, 40 deep, is a DAG of 40 nodes whose tree has 2⁴⁰:
/// each stage must work on the DAG (emission once rendered a base twice per
/// level, 45 s at 20 levels).
#[test]
fn chained_definitions_expand_in_time_linear_in_the_dag() {
    let defs: Vec<String> = (1..=40)
        .map(|i| format!("d{i} = d{} * d{} + x", i - 1, i - 1))
        .collect();
    let body = format!(
        "struct S {{ coordinates: [x, y], mass: diag[1.0, 1.0], definitions: [d0 = x * y + x.sin(), {}], \
         forces: [d40, 0.0], constraints: [y == d40] }}",
        defs.join(", ")
    );
    let code = finishes(body).expect("accepted");
    assert!(code.len() < 1_000_000, "{} bytes", code.len());
}

#[test]
fn nested_compositions_expand() {
    let mut sin = "x".to_string();
    let mut usinu = "x".to_string();
    for _ in 0..120 {
        sin = format!("{sin}.sin()");
    }
    for _ in 0..12 {
        usinu = format!("(({usinu}) * ({usinu}).sin())");
    }
    for e in [sin, usinu] {
        let body = format!(
            "struct S {{ coordinates: [x, y], mass: diag[1.0, 1.0], forces: [{e}, 0.0], constraints: [y == {e}] }}"
        );
        finishes(body).expect("accepted");
    }
}

/// Expanded size of a constraint and force built from a chain of `n`
/// definitions (`link(i)` defines `dᵢ` from `dᵢ₋₁`, `d0 = x`).
fn chain_size(n: usize, link: impl Fn(usize) -> String) -> usize {
    let defs: Vec<String> = (1..=n).map(&link).collect();
    let body = format!(
        "struct S {{ coordinates: [x, y], mass: diag[1.0, 1.0], definitions: [d0 = x, {}], \
         forces: [d{n}, 0.0], constraints: [y == d{n}] }}",
        defs.join(", ")
    );
    finishes(body).expect("accepted").len()
}

/// A composition n deep is a DAG of O(n) nodes; its second derivative
/// (the constraint's `b`) must be too, and so the emitted code and text.
/// Flattening every product made both O(n²): `sin` 200 deep gave 3.3 MB,
/// now 0.2 MB. Doubling the depth must at most double the output (2.3×
/// allows for the fixed part); quadratic growth would give 4×.
#[test]
fn output_grows_linearly_with_the_depth_of_a_composition() {
    let sin = |i: usize| format!("d{i} = d{}.sin()", i - 1);
    let usinu = |i: usize| format!("d{i} = d{} * d{}.sin()", i - 1, i - 1);
    for (name, link, depths) in [
        (
            "sin∘sin∘…",
            &sin as &dyn Fn(usize) -> String,
            [100, 200, 400],
        ),
        ("u·sin(u)", &usinu, [24, 48, 96]),
    ] {
        let sizes: Vec<usize> = depths.iter().map(|&n| chain_size(n, link)).collect();
        for (pair, depth) in sizes.windows(2).zip(&depths[1..]) {
            let ratio = pair[1] as f64 / pair[0] as f64;
            println!(
                "{name} at depth {depth}: {} bytes, {ratio:.2}× the half depth",
                pair[1]
            );
            assert!(ratio < 2.3, "{name}: {sizes:?} bytes at depths {depths:?}");
        }
    }
}

#[test]
fn contradictory_constraints_are_reported() {
    rejected(
        "struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [x == 0.0, x == 1.0] }",
        "no state satisfies",
    );
    rejected(
        "struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [x + y == 1.0, 2.0 * x + 2.0 * y == 3.0] }",
        "no state satisfies",
    );
    rejected(
        "struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [dot(x) == 1.0, dot(x) == 2.0] }",
        "no state satisfies",
    );
    // Redundant but consistent, and contradictory only for some parameter
    // values: accepted.
    for body in [
        "struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [x == 1.0, 2.0 * x == 2.0] }",
        "struct S { coordinates: [x, y], parameters: [a, b], mass: diag[1.0, 1.0], constraints: [x == a, x == b] }",
    ] {
        assert!(outcome(body).is_ok(), "{body}");
    }
}

/// Found by the fuzz harness: `atan2(y, 0)` differentiates to a row of `A`
/// that simplifies to zero, and `S = A M⁻¹ Aᵀ` with it; the k = 1 solve
/// named a local that was never bound ("cannot find value `__s0_0`").
#[test]
fn a_constraint_whose_row_of_a_vanishes_expands_to_code_that_binds_s() {
    let code = outcome(
        "pub struct S { coordinates: [q0], mass: diag[1.0], \
         constraints: [(dot(q0) + q0).atan2(3.0 * q0 * 0.0)] }",
    )
    .expect("accepted");
    assert!(!code.contains("__s0_0"), "S is structurally zero: {code}");
}

/// Found by the fuzz harness (seed 29322516971171): a coefficient of a sum
/// that overflowed f64 in the derivation (not a constant node, so the
/// overflow check missed it) reached emission and panicked there.
#[test]
fn overflowing_coefficients_of_sums_are_reported_not_a_panic() {
    rejected(
        "pub struct Fuzzed { coordinates: [q0, q1, q2, q3], parameters: [p0], \
         mass: diag[3.0, p0, 0.5, 2.0], \
         constraints: [(hypot((1e150 / dot(q3)), max(1e150, t))).atan2(1e150) == clamp(t, 1.0, 1e9)] }",
        "overflows f64",
    );
}

/// Found by the fuzz harness (seed 19728956540596): `#[doc = ".."]` mutated
/// into `#[mass = ".."]` was forwarded to the struct, which then did not
/// compile. Only built-in attributes and standard derives are forwarded.
#[test]
fn unknown_attributes_and_derives_are_rejected_not_forwarded() {
    rejected(
        "#[mass = \"text\"] struct S { coordinates: [x], mass: diag[1.0] }",
        "cannot be forwarded",
    );
    rejected(
        "#[derive(serde::Serialize)] struct S { coordinates: [x], mass: diag[1.0] }",
        "standard derives",
    );
    for fine in [
        "#[doc = \"A system.\"] #[allow(dead_code)] #[derive(Hash, Eq)] struct S { coordinates: [x], mass: diag[1.0] }",
        "#[deprecated] #[must_use] struct S { coordinates: [x], mass: diag[1.0] }",
    ] {
        assert!(outcome(fine).is_ok(), "{fine}");
    }
}

/// Found by the fuzz harness: `#[doc = dot]` (a mutated doc comment) is not
/// an attribute rustc accepts.
#[test]
fn malformed_forwarded_attributes_are_rejected() {
    for attr in [
        "#[doc = dot]",
        "#[allow(1.0)]",
        "#[must_use(x)]",
        "#[derive]",
        "#[doc]",
    ] {
        rejected(
            &format!("{attr} struct S {{ coordinates: [x], mass: diag[1.0] }}"),
            "malformed attribute",
        );
    }
}

/// Control inputs enter through `forces` only (issue 12): anywhere else is
/// an error at that section, also through a definition; in forces, also
/// through a definition, they are accepted.
#[test]
fn inputs_outside_forces_are_spanned_errors() {
    let why = "control inputs may appear in `forces` only";
    for body in [
        "struct S { coordinates: [x], inputs: [u], mass: diag[u], forces: [u] }",
        "struct S { coordinates: [x, y], inputs: [u], mass: diag[1.0, 1.0], constraints: [x == u] }",
        "struct S { coordinates: [x, y], inputs: [u], definitions: [d = u * x], mass: diag[1.0, 1.0], constraints: [y == d] }",
        "struct S { coordinates: [x], inputs: [u], kinetic_energy: u * dot(x).powi(2) }",
        "struct S { coordinates: [x], inputs: [u], kinetic_energy: dot(x).powi(2), potential_energy: u * x }",
    ] {
        rejected(body, why);
    }
    let code = outcome(
        "struct S { coordinates: [x, y], parameters: [k], inputs: [u, v], definitions: [d = k * u], \
         mass: diag[1.0, 1.0], forces: [d, v * y], constraints: [x == y] }",
    )
    .expect("inputs in forces, through a definition");
    assert!(code.contains("INPUTS : usize = 2"), "INPUTS emitted");
}
