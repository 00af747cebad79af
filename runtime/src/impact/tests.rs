use super::*;
use nalgebra::{Matrix1x2, Matrix2, Matrix2x3, Matrix3, Vector1, Vector2, Vector3};

/// A bob of mass `m` on a rod of length `l` from the origin, at angle `θ`
/// from the downward vertical with angular velocity `ω`, hits the wall
/// `x ≤ w` (gap `w − x`): the rod is the persistent row `x ẋ + y ẏ = 0`.
#[test]
fn pendulum_on_a_wall_rebounds_with_minus_e_times_its_angular_velocity() {
    for &(theta, omega, e) in &[(0.3, 2.0, 0.5), (1.1, -0.7, 0.0), (-0.4, 3.3, 1.0)] {
        let (m, l) = (1.7f64, 0.9);
        let (x, y) = (l * f64::sin(theta), -l * f64::cos(theta));
        let qd = Vector2::new(l * omega * f64::cos(theta), l * omega * f64::sin(theta));
        let mass = Matrix2::identity() * m;
        let a = Matrix1x2::new(x, y);
        let residual = a * qd;
        let gap = Matrix1x2::new(-1.0, 0.0);
        let hit: Impact<f64, 2, 2> =
            impact_with_gaps(&mass, &a, &residual, &gap, &[true], &[e], &qd).unwrap();
        // ω⁺ from the velocity: (x ẏ − y ẋ) / l².
        let omega_after = (x * hit.qd[1] - y * hit.qd[0]) / (l * l);
        assert!(
            (omega_after + e * omega).abs() <= 1e-15 * omega.abs(),
            "{omega_after}"
        );
        // The rod holds: x ẋ + y ẏ = 0.
        assert!((a * hit.qd)[0].abs() < 1e-15);
        // The impulse is Aᵀ λ and M Δq̇.
        let p = Matrix2x3::new(x, -1.0, 0.0, y, 0.0, 0.0);
        let lam = Vector3::new(hit.row_impulses[0], hit.row_impulses[1], 0.0);
        assert!((p * lam - hit.impulse).amax() < 1e-14);
        assert!((mass * (hit.qd - qd) - hit.impulse).amax() < 1e-14);
    }
}

#[test]
fn two_bodies_conserve_momentum_and_rebound_with_restitution() {
    let (m1, m2, e) = (2.0f64, 3.0, 0.6);
    let mass = Matrix2::new(m1, 0.0, 0.0, m2);
    let qd = Vector2::new(1.5, -0.5);
    // Gap x₂ − x₁ − d ≥ 0.
    let a = Matrix1x2::new(-1.0, 1.0);
    let target = Vector1::new(-e * (a * qd)[0]);
    let hit = impact_map(&mass, &a, &target, &[true], &qd).unwrap();
    // The closed form of a central collision.
    let (u1, u2) = (qd[0], qd[1]);
    let v1 = (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2);
    let v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2);
    assert!((hit.qd[0] - v1).abs() < 1e-15 && (hit.qd[1] - v2).abs() < 1e-15);
    let momentum = |v: &Vector2<f64>| m1 * v[0] + m2 * v[1];
    assert!((momentum(&hit.qd) - momentum(&qd)).abs() < 1e-14);
    // The impulse on body 2 is +λ, on body 1 −λ.
    assert!((hit.impulse[1] - m2 * (v2 - u2)).abs() < 1e-14);
    assert!((hit.row_impulses[0] - hit.impulse[1]).abs() < 1e-15);
    // In f32 too.
    let hit32 = impact_map(
        &mass.cast::<f32>(),
        &a.cast::<f32>(),
        &target.cast::<f32>(),
        &[true],
        &qd.cast::<f32>(),
    )
    .unwrap();
    assert!((hit32.qd[0] - v1 as f32).abs() < 1e-6);
}

#[test]
fn inactive_rows_take_no_part() {
    let mass = Matrix2::identity();
    let qd = Vector2::new(1.0, -2.0);
    let a = Matrix2::new(1.0, 0.0, 0.0, 1.0);
    let target = Vector2::new(7.0, 0.0);
    let hit = impact_map(&mass, &a, &target, &[false, true], &qd).unwrap();
    assert_eq!(hit.qd, Vector2::new(1.0, 0.0));
    assert_eq!(hit.row_impulses[0], 0.0);
    let none = impact_map(&mass, &a, &target, &[false, false], &qd).unwrap();
    assert_eq!(none.qd, qd);
}

/// A gap whose row repeats a persistent constraint's (a redundant contact)
/// is solved when consistent, with the impulse of the single row; parallel
/// rows asking for different velocities are `Unsatisfiable`.
#[test]
fn redundant_rows_by_the_rank_rule() {
    let mass = Matrix3::from_diagonal(&Vector3::new(1.0f64, 2.0, 4.0));
    let qd = Vector3::new(1.0, -1.0, 0.5);
    let row = [1.0, 2.0, -1.0];
    let a1 = nalgebra::Matrix1x3::new(row[0], row[1], row[2]);
    let one = impact_map(&mass, &a1, &Vector1::new(0.25), &[true], &qd).unwrap();
    // The same row twice, scaled, with consistent targets.
    let a2 = Matrix2x3::new(
        row[0],
        row[1],
        row[2],
        3.0 * row[0],
        3.0 * row[1],
        3.0 * row[2],
    );
    let two = impact_map(&mass, &a2, &Vector2::new(0.25, 0.75), &[true, true], &qd).unwrap();
    assert!((one.qd - two.qd).amax() < 1e-15, "{} {}", one.qd, two.qd);
    assert!((one.impulse - two.impulse).amax() < 1e-14);
    assert!((a2.transpose() * two.row_impulses - two.impulse).amax() < 1e-14);
    // Contradictory targets: no velocity satisfies both.
    let bad = impact_map(&mass, &a2, &Vector2::new(0.25, 0.5), &[true, true], &qd);
    assert_eq!(bad, Err(DynamicsError::Unsatisfiable));
    // Nearly parallel rows (1e-5 rad apart, below the LDLᵀ's 1e-3 rad
    // tolerance) with independent targets: the minimum-norm solve keeps
    // both, and both hold.
    let a3 = Matrix2x3::new(1.0, 0.0, 0.0, 1.0, 1e-5, 0.0);
    let near = impact_map(&mass, &a3, &Vector2::new(0.0, 1e-5), &[true, true], &qd).unwrap();
    assert!(
        (near.qd[0]).abs() < 1e-15 && (near.qd[1] - 1.0).abs() < 1e-9,
        "{}",
        near.qd
    );
}

#[test]
fn errors_are_values() {
    let qd = Vector2::new(1.0, 0.0);
    let a = Matrix1x2::new(1.0, 0.0);
    let t = Vector1::new(0.0);
    let nan = Matrix2::new(f64::NAN, 0.0, 0.0, 1.0);
    assert_eq!(
        impact_map(&nan, &a, &t, &[true], &qd),
        Err(DynamicsError::NonFinite)
    );
    let inf = Vector2::new(f64::INFINITY, 0.0);
    let m = Matrix2::identity();
    assert_eq!(
        impact_map(&m, &a, &t, &[true], &inf),
        Err(DynamicsError::NonFinite)
    );
    // M = diag(1, 0) and a row on the first coordinate: the second is free
    // of mass and of constraint, so no minimiser.
    let semi = Matrix2::new(1.0, 0.0, 0.0, 0.0);
    assert_eq!(
        impact_map(&semi, &a, &t, &[true], &qd),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
}

/// A massless coordinate fixed by the impacting row: the auxiliary metric
/// `M + s AᵀA` has the same minimiser, and the impulse is `M Δq̇`.
#[test]
fn semidefinite_mass_through_the_auxiliary_metric() {
    let semi = Matrix2::new(2.0f64, 0.0, 0.0, 0.0);
    let qd = Vector2::new(1.0, 3.0);
    let a = Matrix1x2::new(0.0, 1.0);
    let hit = impact_map(&semi, &a, &Vector1::new(-1.0), &[true], &qd).unwrap();
    assert_eq!(hit.qd, Vector2::new(1.0, -1.0));
    assert_eq!(hit.impulse, Vector2::zeros());
    assert!(hit.row_impulses[0].abs() < 1e-14, "{}", hit.row_impulses);
}
