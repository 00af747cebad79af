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

/// An integer exponent beyond `i32` made by folding (`(4⁴)⁴ = 2³²`, which
/// the parser's bound on `powi` never sees) is emitted as `powf` of its
/// value: `powi` would have wrapped it to `x⁰ = 1`.
#[test]
fn a_folded_exponent_beyond_i32_is_not_wrapped() {
    let code = outcome(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [x.powf(4.0.powi(4).powi(4))] }",
    )
    .expect("accepted");
    assert!(code.contains("powf"), "emitted as powf: {code}");
    assert!(
        code.contains("4294967296f64"),
        "the exponent's value: {code}"
    );
    assert!(!code.contains(". powi (0"), "no wrapped exponent: {code}");
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
/// overflow check missed it) reached emission and panicked there. The
/// power of a sum's content (here 1e150's) leaves the sum only where it
/// is moderate (`expr::build`), so none overflows: the input expands, and
/// every constant in its code is finite.
#[test]
fn overflowing_coefficients_of_sums_are_not_a_panic() {
    let code = outcome(
        "pub struct Fuzzed { coordinates: [q0, q1, q2, q3], parameters: [p0], \
         mass: diag[3.0, p0, 0.5, 2.0], \
         constraints: [(hypot((1e150 / dot(q3)), max(1e150, t))).atan2(1e150) == clamp(t, 1.0, 1e9)] }",
    )
    .expect("no coefficient overflows");
    let literals: Vec<f64> = code
        .split("lit :: < T > (")
        .skip(1)
        .map(|rest| {
            rest[..rest.find("f64").expect("an f64 literal")]
                .parse()
                .expect("a number")
        })
        .collect();
    assert!(
        literals.iter().any(|v| *v >= 1e150),
        "the model's 1e150 is there"
    );
    assert!(literals.iter().all(|v| v.is_finite()), "{literals:?}");
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

/// Issue 30: a kinetic energy that only looks quadratic at the velocities
/// a sampling check draws (positive, below 1) is rejected, decided on the
/// expression: a velocity under a function or a fractional power, and a
/// term of degree above 2 however small or far away its coefficient.
/// `|ẋ|·ẋ/2 + ẋ²` once gave `M = 3` and `q̈ = −1/3` where Lagrange's
/// equations give −1.
#[test]
fn kinetic_energy_that_is_not_quadratic_in_the_velocities_is_rejected() {
    let why = "must be a polynomial of degree at most 2 in the velocities";
    for (t, detail) in [
        ("dot(x).abs() * dot(x) / 2.0 + dot(x).powi(2)", "`abs`"),
        ("dot(x).abs() * dot(x)", "`abs`"),
        ("dot(x).max(0.0).powi(2)", "`max`"),
        ("dot(x).clamp(-1.0, 1.0).powi(2)", "under the function"),
        ("dot(x).signum() * dot(x).powi(2)", "`signum`"),
        ("dot(x).hypot(dot(x))", "fractional power"),
        ("dot(x).powi(2).sqrt()", "fractional power"),
        ("dot(x).powf(2.5)", "fractional power"),
        ("dot(x).powi(3) / x.powi(2) + 1.0 / dot(x)", "denominator"),
        (
            "(x - 5.0).max(0.0) * dot(x).powi(4) + dot(x).powi(2)",
            "degree 4",
        ),
        (
            "dot(x).powi(3) * (x - 1.0).sqrt() + dot(x).powi(2)",
            "degree 3",
        ),
        ("1e-12 * dot(x).powi(4) + dot(x).powi(2) / 2.0", "degree 4"),
        ("dot(x).powi(2) * 2.0.powf(dot(x))", "variable exponent"),
        ("dot(x).sin().powi(2)", "`sin`"),
        ("(dot(x) + x.exp()).powi(3)", "degree 3"),
    ] {
        let body = format!("struct S {{ coordinates: [x], kinetic_energy: {t} }}");
        match outcome(&body) {
            Err(e) => assert!(
                e.contains(why) && e.contains(detail),
                "{t}: expected an error about {why:?} ({detail}), got {e:?}"
            ),
            Ok(_) => panic!("accepted a kinetic energy that is not quadratic: {t}"),
        }
    }
    // Two velocities, one of them under a function.
    rejected(
        "struct S { coordinates: [x, y], kinetic_energy: dot(x).powi(2) + dot(y).powi(2) + dot(x).abs() * dot(y) }",
        why,
    );
}

/// What is quadratic in the velocities stays accepted: coefficients may be
/// any function of the coordinates, `t` and parameters (kinks included),
/// velocities may sit in sums raised to the second power, and terms of
/// higher degree that cancel symbolically are no obstacle.
#[test]
fn kinetic_energy_quadratic_in_the_velocities_with_any_coefficients_is_accepted() {
    for t in [
        "(x.cos() + 2.0) * dot(x).powi(2) / 2.0 + x.abs() * dot(x) + (dot(x) + dot(y)).powi(2) + dot(y).powi(2)",
        "(2.0 + (x - 5.0).max(0.0)) * dot(x).powi(2) + (x * y).hypot(1.0) * dot(y).powi(2) + t.sin() * dot(y)",
        "(dot(x) * x.cos()).hypot(dot(y) * 2.0).powi(2) + dot(x).powi(2)",
        "m / 2.0 * (dt(x * y.cos()).powi(2) + dt(x * y.sin()).powi(2)) + dot(y).powi(2) + (m * x).signum() * dot(x)",
        "dot(x).powf(2.0) + dot(y).powf(2.0) / 2.0",
    ] {
        let body = format!(
            "struct S {{ coordinates: [x, y], parameters: [m], kinetic_energy: {t} }}"
        );
        if let Err(e) = outcome(&body) {
            panic!("rejected a quadratic kinetic energy {t}: {e}");
        }
    }
}

/// A polynomial of degree above 2 whose extra terms cancel only once
/// multiplied out, `(ẋ + ẏ)³ − ẋ³ − 3ẋ²ẏ − 3ẋẏ² − ẏ³ + ẋ² + ẏ²`: still
/// quadratic, still accepted (the third derivatives vanish).
#[test]
fn kinetic_energy_whose_cubic_terms_cancel_is_accepted() {
    let t = "(dot(x) + dot(y)).powi(3) - dot(x).powi(3) - 3.0 * dot(x).powi(2) * dot(y) \
             - 3.0 * dot(x) * dot(y).powi(2) - dot(y).powi(3) + dot(x).powi(2) + dot(y).powi(2)";
    let body = format!("struct S {{ coordinates: [x, y], kinetic_energy: {t} }}");
    if let Err(e) = outcome(&body) {
        panic!("rejected a quadratic kinetic energy: {e}");
    }
}

/// Issue 30: constants finite as written that overflow (or are NaN) where
/// the generated code evaluates them are compile errors, wherever they
/// occur: `E.powi(710)` once reached the Jacobian and `linearize` as NaN.
#[test]
fn constants_that_overflow_only_when_evaluated_are_rejected() {
    for (body, why) in [
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [E.powi(710) * x] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [PI.powi(1000)] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [PI.powi(-1000) * x] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [x / E.powi(710)] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [10.0.powf(500.5) * x] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [1000.0.exp() * x.sin()] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [0.0.ln() + x] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [2.0.asin() * x] }", "NaN"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [(-1.0).sqrt() * x] }", "NaN"),
        ("struct S { coordinates: [x], mass: diag[E.powi(710)] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [x.powf(E.powi(710))] }", "overflows f64"),
        ("struct S { coordinates: [x], mass: diag[1.0], forces: [(E.powi(710) - 1.0).atan() * x] }", "overflows f64"),
        ("struct S { coordinates: [x, y], mass: diag[1.0, 1.0], constraints: [x * PI.powi(1000) == y] }", "overflows f64"),
        ("struct S { coordinates: [x], kinetic_energy: E.powi(710) * dot(x).powi(2) }", "overflows f64"),
        ("struct S { coordinates: [x], kinetic_energy: dot(x).powi(2), potential_energy: 1000.0.exp() * x }", "overflows f64"),
    ] {
        rejected(body, why);
    }
    // In range: accepted.
    for body in [
        "struct S { coordinates: [x], mass: diag[1.0], forces: [E.powi(709) * x] }",
        "struct S { coordinates: [x], mass: diag[1.0], forces: [PI.powi(600) * PI.powi(-600) * x] }",
        "struct S { coordinates: [x], mass: diag[1.0], forces: [700.0.exp() * x + 2.0.sqrt() + 0.5.ln()] }",
        "struct S { coordinates: [x], mass: diag[1.0], forces: [10.0.powf(300.5) * x] }",
    ] {
        if let Err(e) = outcome(body) {
            panic!("rejected {body}: {e}");
        }
    }
}

/// A seeded family of kinetic energies (issue 30's fuzz of the energy
/// surface): quadratic forms in two velocities whose coefficients are
/// random functions of the coordinates and `t` (kinks included) are
/// accepted; the same forms with one hostile term added (a velocity under
/// a function or a fractional power, or a term of degree 3 or 4 with a
/// tiny or far-away coefficient) are rejected with the quadratic error.
/// None panics.
#[test]
fn seeded_kinetic_energies_are_accepted_exactly_when_quadratic() {
    let mut seed = 0x5eed_0030_u64;
    let mut next = |n: usize| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as usize) % n
    };
    let coefficients = [
        "1.0",
        "(x.cos() + 2.0)",
        "(x - 5.0).max(0.0)",
        "y.abs()",
        "(x * y).hypot(1.0)",
        "(t.sin() + 1.5)",
        "x.signum()",
        "1e-12",
        "(x - 1.0).sqrt()",
        "y.clamp(-1.0, 1.0)",
    ];
    let monomials = [
        "dot(x).powi(2)",
        "dot(y).powi(2)",
        "dot(x) * dot(y)",
        "dot(x)",
        "dot(y)",
    ];
    let hostile = [
        "dot(x).abs() * dot(x)",
        "dot(y).max(0.0).powi(2)",
        "dot(x).clamp(-1.0, 1.0).powi(2)",
        "dot(y).signum() * dot(y).powi(2)",
        "dot(x).hypot(dot(y))",
        "dot(x).powi(2).sqrt()",
        "dot(x).powi(3)",
        "dot(x).powi(2) * dot(y).powi(2)",
        "(dot(x) + y).powi(3)",
        "dot(y).cos()",
        "dot(x).exp()",
        "1.0 / (1.0 + dot(x).powi(2))",
    ];
    let (mut accepted, mut rejected_count) = (0, 0);
    for case in 0..120 {
        let terms: Vec<String> = (0..1 + next(4))
            .map(|_| {
                format!(
                    "{} * {}",
                    coefficients[next(coefficients.len())],
                    monomials[next(monomials.len())]
                )
            })
            .collect();
        // Positive definite for certain: both squares with weight 1.
        let quadratic = format!("dot(x).powi(2) + dot(y).powi(2) + {}", terms.join(" + "));
        let bad = format!(
            "{quadratic} + {} * {}",
            coefficients[next(coefficients.len())],
            hostile[next(hostile.len())]
        );
        for (t, valid) in [(quadratic, true), (bad, false)] {
            let body = format!("struct S {{ coordinates: [x, y], kinetic_energy: {t} }}");
            match (outcome(&body), valid) {
                (Ok(_), true) => accepted += 1,
                (Err(e), false) if e.contains("polynomial of degree at most 2") => {
                    rejected_count += 1
                }
                (result, _) => panic!("case {case}, {t}: valid {valid}, got {result:?}"),
            }
        }
    }
    assert_eq!((accepted, rejected_count), (120, 120));
}

/// A kinetic energy whose mass matrix is negative is an error, also where
/// `M` is constant only once `sin² + cos² = 1` is applied (the check runs
/// after the identities, which `M` now gets together with `F`).
#[test]
fn a_negative_kinetic_energy_is_an_error() {
    let why = "not positive semi-definite";
    rejected(
        "struct S { coordinates: [x], kinetic_energy: -dot(x).powi(2) / 2.0 }",
        why,
    );
    rejected(
        "struct S { coordinates: [th], definitions: [px = th.sin(), py = th.cos()], \
         kinetic_energy: -(dt(px).powi(2) + dt(py).powi(2)) / 2.0 }",
        why,
    );
    // The same pendulum with a positive energy is accepted.
    assert!(outcome(
        "struct S { coordinates: [th], definitions: [px = th.sin(), py = th.cos()], \
         kinetic_energy: (dt(px).powi(2) + dt(py).powi(2)) / 2.0 }"
    )
    .is_ok());
}
