//! The explicit Gibbs–Appell equation on Appell's example: with
//! `eliminate: [x]` and φ written as (ẋ² + ẏ² − ż²)/2 = α h, the generated
//! system is the paper's eq. 33 entry by entry; at ẋ = 0 it re-pivots; at
//! rest (A = 0) it reports the rank deficiency.

use constrained::models::Appell;
use constrained::nalgebra::{Matrix3, Vector3};
use constrained::GibbsAppellError;
use proptest::prelude::*;

mod common;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(10_000))]

    #[test]
    fn eq33_entry_by_entry((q, qd, t, g, alpha) in common::appell_state()) {
        let [xd, yd, zd] = qd;
        prop_assume!(xd.abs() > 0.1);
        let sys = Appell::new(g, alpha);
        let (s, rhs) = sys.gibbs_appell_matrices(&Vector3::from(q), &Vector3::from(qd), t).unwrap();
        // Eq. 33 with h = z: b = α (h_x ẋ + h_y ẏ + h_z ż + h_t) = α ż.
        let b = alpha * zd;
        let x2 = xd * xd;
        let expected = Matrix3::new(
            xd, yd, -zd,
            0.0, 1.0 + yd * yd / x2, -yd * zd / x2,
            0.0, -yd * zd / x2, 1.0 + zd * zd / x2,
        );
        let expected_rhs = Vector3::new(b, b * yd / x2, -g - b * zd / x2);
        for i in 0..3 {
            for j in 0..3 {
                let e = expected[(i, j)];
                prop_assert!((s[(i, j)] - e).abs() <= 1e-12 * e.abs().max(1.0), "S[{i},{j}] = {} vs eq. 33 {e}", s[(i, j)]);
            }
            let e = expected_rhs[i];
            let scale = e.abs().max(g).max((b * yd / x2).abs() + (b * zd / x2).abs());
            prop_assert!((rhs[i] - e).abs() <= 1e-12 * scale, "s[{i}] = {} vs eq. 33 {e}", rhs[i]);
        }
    }
}

#[test]
fn re_pivots_where_the_eliminated_column_vanishes() {
    let sys = Appell::new(9.81, 0.5);
    let (q, qd) = (Vector3::new(0.3, -0.2, 1.1), Vector3::new(0.0, 0.7, -0.4));
    let (s, rhs) = sys
        .gibbs_appell_matrices(&q, &qd, 0.0)
        .expect("A keeps rank 1");
    let via_gibbs_appell = sys
        .acceleration_gibbs_appell(&q, &qd, 0.0)
        .expect("re-pivoted");
    let via_inverse = sys.acceleration(&q, &qd, 0.0);
    assert!(
        (via_gibbs_appell - via_inverse).norm() < 1e-12,
        "{via_gibbs_appell} vs {via_inverse}"
    );
    assert!((s * via_inverse - rhs).norm() < 1e-12);
    // Re-pivoted to the largest column, ẏ: the rows of eq. 13 no longer
    // involve ÿ, and do involve ẍ.
    assert_eq!((s[(1, 1)], s[(2, 1)]), (0.0, 0.0));
    assert_ne!(s[(1, 0)], 0.0);
}

#[test]
fn at_rest_the_partition_is_undefined() {
    let sys = Appell::new(9.81, 0.5);
    let (q, qd) = (Vector3::new(0.3, -0.2, 1.1), Vector3::zeros());
    assert_eq!(
        sys.gibbs_appell_matrices(&q, &qd, 0.0),
        Err(GibbsAppellError::RankDeficient)
    );
    assert_eq!(
        sys.acceleration_gibbs_appell(&q, &qd, 0.0),
        Err(GibbsAppellError::RankDeficient)
    );
    // The generalized-inverse form is defined there.
    assert_eq!(
        sys.acceleration(&q, &qd, 0.0),
        Vector3::new(0.0, 0.0, -9.81)
    );
}
