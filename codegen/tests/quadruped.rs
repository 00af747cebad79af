//! The quadruped of `examples/support/quadruped.rs` (a floating base in a
//! unit quaternion, twelve joints, four feet fixed: 19 coordinates, 13
//! rows), as the generator solves it: the auxiliary mass takes the
//! quaternion's norm alone (the feet's rows would couple the base with
//! every leg in it), and the operations of `q̈` and of `A`, `b` stay at
//! or below today's counts (19,747 and 4,173 before the solve by forward
//! substitution, the row choice and `b` by forward mode; 12,904 and 2,944
//! before the saddle-point solve and the feet's positions built along
//! their chains; 9,114 before the velocity coordinates, 8,361 before their
//! scale ½, 8,094 before the base's own axes: `A` and `b` then rose from
//! 1,320 to 1,480, the quotient of `R(q/|q|)` in their quaternion columns;
//! 6,928 before each leg was eliminated through its foot's rows, 6,325
//! before the recursions held their momenta; 144 of the operations were
//! divisions by `|q|²` before they shared its reciprocal), and
//! `gauss` solves in the quaternion's velocity coordinates, in the base's
//! axes, each leg's joints eliminated through its foot's rows in closed
//! form (`θ̈ = J⁻¹ (b − E u)`) and the base's six unknowns from its
//! inertia with the feet held.

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
    let eq =
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
    let ops = op_count::acceleration(&file).expect("a generated solve");
    let total = ops.total();
    assert!(total <= 6_006, "q̈ costs {total} operations");
    // |q|² divides 144 products: one reciprocal, then multiplications
    // (a division is several times a multiplication's cost, and LLVM may
    // not trade one for the other).
    assert!(ops.div <= 20, "q̈ divides {} times", ops.div);
    let ab = op_count::method(&file, "constraint_matrices")
        .expect("A and b")
        .total();
    assert!(ab <= 1_425, "A and b cost {ab} operations");
}

/// `gauss` eliminates each leg through its foot's rows (the cofactors of
/// each foot's `J`, a determinant test per leg, the base's 6 × 6 `S`), not
/// by the saddle-point factorization: none of its signed pivots is left.
/// The four legs have one structural pattern, so their factor code (each
/// `J⁻¹` after its test, its share of `S` and `r`) is written once, as a
/// function `gauss` defines and calls per leg.
#[test]
fn each_leg_is_solved_through_its_foot() {
    let expanded = expand_with(quadruped(), Options { jacobians: false }).expect("it expands");
    let text = expanded.to_string();
    let gauss = &text[text.find("fn gauss <").expect("a generated gauss")..];
    assert_eq!(gauss.matches("fn __leg_share").count(), 1, "one copy");
    let shared = &gauss[gauss.find("fn __leg_share").expect("the shared code")..];
    assert!(shared.contains("let __ljd0 ="), "det J, tested in it");
    for leg in 0..4 {
        assert!(
            gauss.contains(&format!("Some (__ljo{leg}) = __leg_share")),
            "leg {leg}'s call"
        );
    }
    assert!(!gauss.contains("__ljo4"), "four legs");
    assert!(
        !gauss.contains("let __ljd1 ="),
        "no leg's factor written out"
    );
    assert!(gauss.contains("let __bsd5 ="), "the base's six pivots");
    assert!(!gauss.contains("let __kd0 ="), "no saddle-point pivot");
}

/// Legs of different structural patterns keep their factor code written
/// out per leg: with the front left hip turning about `z` instead of `x`,
/// that foot's first row moves with it (a structural nonzero the others'
/// have not), and no shared function is written.
#[test]
fn legs_of_different_patterns_are_written_out_each() {
    let text = constrained_codegen::tools::fixtures::quadruped()
        .expect("the workspace's quadruped")
        .replace(
            "revolute(fl_haa, [1.0, 0.0, 0.0])",
            "revolute(fl_haa, [0.0, 0.0, 1.0])",
        );
    let tokens = text.parse().expect("the model is tokens");
    let expanded = expand_with(tokens, Options { jacobians: false }).expect("it expands");
    let text = expanded.to_string();
    let gauss = &text[text.find("fn gauss <").expect("a generated gauss")..];
    assert!(!gauss.contains("fn __leg_share"), "no shared function");
    for leg in 0..4 {
        assert!(
            gauss.contains(&format!("let __ljd{leg} =")),
            "leg {leg}'s det J, written out"
        );
    }
}

/// The velocity form (`equations::velocity`) of the saddle-point system
/// (`equations::saddle_point`): chosen for the quadruped, with the
/// quaternion's `α` (coordinate 3) solved from the norm's row (row 12)
/// alone, so the saddle-point system keeps 18 coordinates — the base's
/// position and `β`, the legs — and the feet's 12 rows. Its order takes
/// every coordinate before any row (a row's pivot is then `S`'s, away from
/// zero at a straightened leg too), and the legs' solve eliminates each
/// foot with its own leg: its three joints and its three rows, the feet
/// meeting only in the base's Schur complement.
#[test]
fn each_foot_is_eliminated_with_its_leg() {
    let eq =
        analyse_with(quadruped(), Options { jacobians: false }).expect("the quadruped is valid");
    let MassInverse::Auxiliary(f) = &eq.mass_inverse else {
        panic!("the auxiliary solve");
    };
    let velocity = f.velocity.as_ref().expect("the velocity form is chosen");
    assert_eq!(velocity.system.quaternions, vec![(3, 12)]);
    let mut kept: Vec<usize> = (0..19).collect();
    kept.remove(3);
    assert_eq!(velocity.coordinates, kept);
    assert_eq!(velocity.rows, (0..12).collect::<Vec<_>>());
    let g = &eq.system.graph;
    // TᵀMT has no α row or column; the norm's row of A T is on α alone.
    assert!((0..19).all(|j| g.is_zero(velocity.mass[3][j])));
    assert!((0..19).all(|j| (j == 3) != g.is_zero(velocity.system.a[12][j])));
    let saddle = &velocity.structure;
    let (n, k) = (18, 12);
    assert_eq!(saddle.len(), n + k);
    let position = |row: usize| {
        saddle
            .order
            .iter()
            .position(|&r| r == row)
            .expect("in order")
    };
    let first_row = (n..n + k).map(position).min().expect("twelve rows");
    assert!(
        (0..n).all(|c| position(c) < first_row),
        "every coordinate before any row"
    );
    let legs = f.legs.as_ref().expect("the legs' solve");
    assert_eq!(legs.base, [0, 1, 2, 3, 4, 5]);
    for (leg, (joints, rows)) in legs.legs.iter().enumerate() {
        let ours = [0, 1, 2].map(|j| 6 + 3 * leg + j);
        assert_eq!(*joints, ours, "leg {leg}'s joints");
        assert_eq!(*rows, [0, 1, 2].map(|j| 3 * leg + j), "leg {leg}'s foot");
    }
    // The feet's rows in the base's axes: `I` on the position, no `α`.
    let one = |e| g.as_num(e).is_some_and(|x| x.is_one());
    for r in 0..12 {
        for j in 0..3 {
            let e = velocity.system.a[r][j];
            assert!(
                if r % 3 == j { one(e) } else { g.is_zero(e) },
                "row {r}, z{j}"
            );
        }
        assert!(g.is_zero(velocity.system.a[r][3]), "row {r}: no α");
    }
}

/// The twin with a fifth, dependent row keeps the range-space form: its
/// rows are dependent, so some multiplier's pivot vanishes at every sample
/// point, and the rank rule must decide instead.
#[test]
fn a_redundant_set_keeps_the_range_space_form() {
    let text = constrained_codegen::tools::fixtures::quadruped()
        .expect("the workspace's quadruped")
        .replace(
            "== [hr_x, hr_y, 0.0],",
            "== [hr_x, hr_y, 0.0], position(fl_lower, [0.0, 0.008, -0.16]).z \
             + position(fr_lower, [0.0, -0.008, -0.16]).z == 0.0,",
        );
    let tokens: proc_macro2::TokenStream = text.parse().expect("tokens");
    let eq = analyse_with(tokens, Options { jacobians: false }).expect("the twin is valid");
    let MassInverse::Auxiliary(f) = &eq.mass_inverse else {
        panic!("the auxiliary solve");
    };
    assert_eq!(eq.a.len(), 14);
    assert!(f.saddle.is_none(), "a dependent row has no safe pivot");
    assert!(f.velocity.is_none(), "nor in the velocity coordinates");
}

/// The derivation says what `acceleration` computes: the solve in the
/// quaternion's velocity coordinates, `α` from the norm's row (row 12,
/// the quaternion at `qw`), then the rest's `L D Lᵀ` in its order, whose
/// coordinates name `β₀…β₂` in place of the quaternion's `qx…qz`.
#[test]
fn the_derivation_describes_the_velocity_solve() {
    let eq =
        analyse_with(quadruped(), Options { jacobians: false }).expect("the quadruped is valid");
    let text = constrained_codegen::emit::derivation::text(&eq, &eq.partition);
    let at = text
        .find("acceleration solves instead, in the quaternions' velocity coordinates")
        .expect("the velocity solve described");
    let part = &text[at..];
    assert!(part.contains("quaternions at qw (row 12)"), "{part}");
    assert!(part.contains("(18 coordinates, 12 rows)"), "{part}");
    let order = part.lines().nth(5).expect("the order's line");
    for name in ["fl_haa", "μ0", "β0", "β1", "β2", "x", "μ11"] {
        assert!(
            order
                .split(", ")
                .any(|s| s.trim() == name || s.trim().starts_with(&format!("{name} "))),
            "{name} in {order}"
        );
    }
    assert!(!order.contains("qx"), "{order}");
}
