//! A Cartesian model given by its energies generates the same code as the
//! same model written with `mass:` and `forces:`: the derived `M` is a
//! constant, so the constant-mass specialisation applies, and the derived
//! `F` is the written one.

use constrained_codegen::expand;

/// The tokens of one generated method, from `pub fn name (` to the next
/// `pub fn`.
fn method(expansion: &str, name: &str) -> String {
    let start = expansion
        .find(&format!("pub fn {name} ("))
        .unwrap_or_else(|| panic!("no `{name}` in the expansion"));
    let rest = &expansion[start + 1..];
    let end = rest.find("pub fn ").map_or(rest.len(), |e| e + 1);
    expansion[start..start + end].to_string()
}

#[test]
fn cartesian_energies_generate_the_same_acceleration_as_mass_and_forces() {
    let written = r#"
        pub struct Pendulum {
            coordinates: [x, y],
            parameters: [m, g, l],
            mass: diag[2.0, 2.0],
            forces: [0.0, -2.0 * g],
            constraints: [x.powi(2) + y.powi(2) == l.powi(2)],
        }"#;
    let from_energies = r#"
        pub struct Pendulum {
            coordinates: [x, y],
            parameters: [m, g, l],
            kinetic_energy: 2.0 * (dot(x).powi(2) + dot(y).powi(2)) / 2.0,
            potential_energy: 2.0 * g * y,
            constraints: [x.powi(2) + y.powi(2) == l.powi(2)],
        }"#;
    let a = expand(written.parse().unwrap()).unwrap().to_string();
    let b = expand(from_energies.parse().unwrap()).unwrap().to_string();
    for name in [
        "mass_matrix",
        "forces",
        "acceleration",
        "constraint_force",
        "constraint_matrices",
    ] {
        assert_eq!(method(&a, name), method(&b, name), "`{name}` differs");
    }
}

/// `sin²x + cos²x == 1` is no constraint at all: the Pythagorean rule
/// reduces it to `0 = 0`, a spanned error, where it used to expand into
/// code that did not compile (a row of A that is identically zero).
#[test]
fn pythagorean_constraint_is_reported_not_emitted() {
    let input = r#"
        pub struct Identity {
            coordinates: [x, y],
            mass: diag[1.0, 1.0],
            constraints: [x.sin().powi(2) + x.cos().powi(2) == 1.0, y == x],
        }"#;
    let error = expand(input.parse().unwrap()).expect_err("no coordinate left");
    assert!(
        error.to_string().contains("involves no coordinate"),
        "{error}"
    );
}
