//! The quadruped of `examples/support/quadruped.rs` (a floating base in a
//! unit quaternion, twelve joints, four feet fixed: 19 coordinates, 13
//! rows), as the generator solves it: the auxiliary mass takes the
//! quaternion's norm alone (the feet's rows would couple the base with
//! every leg in it), and the operations of `q̈` and of `A`, `b` stay at
//! or below today's counts (19,747 and 4,173 before the solve by forward
//! substitution, the row choice and `b` by forward mode).

use constrained_codegen::equations::mass_inverse::MassInverse;
use constrained_codegen::tools::op_count;
use constrained_codegen::{analyse_with, expand_with, Options};

fn quadruped() -> proc_macro2::TokenStream {
    let text =
        constrained_codegen::tools::fixtures::quadruped().expect("the workspace's quadruped");
    text.parse().expect("the model is tokens")
}

#[test]
fn the_auxiliary_mass_takes_the_norm_row_alone() {
    let (eq, _) =
        analyse_with(quadruped(), Options { jacobians: false }).expect("the quadruped is valid");
    let MassInverse::Auxiliary(f) = &eq.mass_inverse else {
        panic!("M is singular along the quaternion: the auxiliary solve");
    };
    let rows = &f.auxiliary.as_ref().expect("auxiliary terms").rows;
    assert_eq!(rows.len(), 1, "one row completes M's rank: {rows:?}");
    let g = &eq.system.graph;
    let row = &eq.a[rows[0]];
    // The base's quaternion is q[3..7]: the norm's gradient 2q is nonzero
    // there and nowhere else.
    for (i, &e) in row.iter().enumerate() {
        assert_eq!(
            !g.is_zero(e),
            (3..7).contains(&i),
            "entry {i} of the chosen row"
        );
    }
}

#[test]
fn the_solve_costs_no_more_than_today() {
    let expanded = expand_with(quadruped(), Options { jacobians: false }).expect("it expands");
    let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
    let total = op_count::acceleration(&file)
        .expect("a generated solve")
        .total();
    assert!(total <= 12_904, "q̈ costs {total} operations");
    let ab = op_count::method(&file, "constraint_matrices")
        .expect("A and b")
        .total();
    assert!(ab <= 2_944, "A and b cost {ab} operations");
}
