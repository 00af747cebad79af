//! The generated N-link chain expands, and its derivation has the expected
//! structure: N position-level constraints, each row of A touching only the
//! coordinates of its two joints.

use constrained_codegen::{analyse, fixtures::planar_chain};

#[test]
fn sixteen_link_chain_structure() {
    let tokens = planar_chain("Chain16", 16).parse().expect("valid tokens");
    let (eq, partition) = analyse(tokens).expect("expands");
    assert_eq!(partition.rank, 16);
    assert!(
        partition.on_surface,
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
