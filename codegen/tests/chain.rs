//! The generated N-link chain expands, and its derivation has the expected
//! structure: N position-level constraints, each row of A touching only the
//! coordinates of its two joints.

use constrained_codegen::{analyse, tools::fixtures::planar_chain};

#[test]
fn sixteen_link_chain_structure() {
    let tokens = planar_chain("Chain16", 16).parse().expect("valid tokens");
    let eq = analyse(tokens).expect("expands");
    assert_eq!(eq.partition.rank, 16);
    assert!(
        eq.partition.on_surface,
        "chain states can be projected onto the constraints"
    );
    assert_eq!(eq.system.dof(), 32);
    assert_eq!(eq.a.len(), 16);
    for (i, row) in eq.a.iter().enumerate() {
        let nonzero: Vec<usize> = (0..32)
            .filter(|&j| !eq.system.graph.is_zero(row[j]))
            .collect();
        let expected: Vec<usize> = if i == 0 {
            vec![0, 1]
        } else {
            (2 * i - 2..2 * i + 2).collect()
        };
        assert_eq!(nonzero, expected, "row {i} of A");
    }
    let generated =
        constrained_codegen::expand(planar_chain("Chain16", 16).parse().unwrap()).unwrap();
    syn::parse2::<syn::File>(generated).expect("valid Rust");
}

/// A constant, non-diagonal mass matrix is inverted exactly at compile time:
/// no factorization of M at run time, and `acceleration` cannot fail.
#[test]
fn constant_mass_needs_no_runtime_factorization() {
    let source = "struct Skew { coordinates: [u, v], mass: [[2.0, 0.5], [0.5, 1.0]], \
                  forces: [0.0, -9.81], constraints: [u.powi(2) + v.powi(2) == 1.0] }";
    let eq = analyse(source.parse().expect("tokens")).expect("analyses");
    assert!(matches!(
        eq.mass_inverse,
        constrained_codegen::equations::mass_inverse::MassInverse::Symbolic(_)
    ));
    assert!(!eq.mass_inverse.is_diagonal());
    let code = constrained_codegen::expand(source.parse().expect("tokens"))
        .expect("expands")
        .to_string();
    let solver = code
        .split("fn gauss")
        .nth(1)
        .and_then(|s| s.split("fn acceleration").next())
        .expect("solver");
    assert!(
        !solver.contains("Cholesky"),
        "the solver factorizes M at run time"
    );
    // M⁻¹ = [[4/7, −2/7], [−2/7, 8/7]]: a = M⁻¹F has a[u] = (2/7)·9.81.
    let derivation = constrained_codegen::emit::derivation::text(
        &eq,
        &constrained_codegen::equations::partition::partition(&eq).expect("partition"),
    );
    assert!(derivation.contains("a[u] = 981/350"), "{derivation}");
}
