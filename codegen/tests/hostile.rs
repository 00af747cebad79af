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

#[test]
fn integer_overflow_in_constant_folding_is_not_a_panic() {
    let _ = outcome(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [-9223372036854775808 * 18446744073709551616 * x] }",
    );
}

#[test]
fn integer_powers_beyond_i32_are_rejected() {
    rejected(
        "struct S { coordinates: [x], mass: diag[1.0], forces: [x.powi(4294967298)] }",
        "powi",
    );
}

#[test]
fn constant_powers_fold_correctly_or_not_at_all() {
    // 2^4294967295 overflows: an error, never 0.5; 1.5^3e9 likewise, never 0.
    for body in [
        "struct S { coordinates: [x], mass: diag[1.0], forces: [2.0.powi(4294967295) * x] }",
        "struct S { coordinates: [x], mass: diag[1.0], forces: [1.5.powi(3000000000) * x] }",
    ] {
        if let Ok(code) = outcome(body) {
            assert!(!code.contains("0.5") && !code.contains("lit (0"), "{code}");
        }
    }
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
