//! A model big enough that the macro differentiates `F`, `M`, `A`, `b`
//! along a direction (forward mode, `Sym::Seed`) rather than column by
//! column: the planar 8-link pendulum in joint angles from its energies
//! (`constrained_chains::PendulumAngles8`), whose dense `M(q)` and
//! `F` depend on every coordinate. Its Jacobians must still be the exact
//! ones: against central differences and dual numbers run through the same
//! generated code.

use constrained::nalgebra::SVector;
use constrained_chains::PendulumAngles8 as Pendulum8;
use num_dual::Dual64;

fn state(seed: u64) -> (SVector<f64, 8>, SVector<f64, 8>) {
    let mut x = seed;
    let mut next = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    (
        SVector::from_fn(|_, _| next()),
        SVector::from_fn(|_, _| next()),
    )
}

/// The largest entry of `a − b` against the scale of `b`.
fn error(a: &SVector<f64, 8>, b: &SVector<f64, 8>) -> f64 {
    (a - b).amax() / b.amax().max(1.0)
}

#[test]
fn directional_jacobians_are_exact() {
    let system = Pendulum8::<f64>::new(9.81);
    let dual = Pendulum8::<Dual64>::new(Dual64::from(9.81));
    let acc = |q: &SVector<f64, 8>, qd: &SVector<f64, 8>| {
        system
            .acceleration(q, qd, 0.0)
            .expect("M is positive definite")
    };
    let (mut central, mut duals, mut dense) = (0.0f64, 0.0f64, 0.0f64);
    for seed in 1..=4 {
        let (q, qd) = state(seed);
        let jac = system
            .acceleration_jacobian(&q, &qd, 0.0)
            .expect("the Jacobians exist");
        let h = 1e-6;
        for c in 0..16 {
            let column = if c < 8 {
                jac.dq.column(c).into_owned()
            } else {
                jac.dqd.column(c - 8).into_owned()
            };
            // Central differences.
            let (mut qp, mut qm, mut qdp, mut qdm) = (q, q, qd, qd);
            if c < 8 {
                qp[c] += h;
                qm[c] -= h;
            } else {
                qdp[c - 8] += h;
                qdm[c - 8] -= h;
            }
            let fd = (acc(&qp, &qdp) - acc(&qm, &qdm)) / (2.0 * h);
            central = central.max(error(&column, &fd));
            // Dual numbers through the same generated code.
            let lift = |v: &SVector<f64, 8>, seeded: Option<usize>| {
                SVector::<Dual64, 8>::from_fn(|i, _| {
                    if seeded == Some(i) {
                        Dual64::new(v[i], 1.0)
                    } else {
                        Dual64::from(v[i])
                    }
                })
            };
            let (dq, dqd) = if c < 8 {
                (lift(&q, Some(c)), lift(&qd, None))
            } else {
                (lift(&q, None), lift(&qd, Some(c - 8)))
            };
            let a = dual
                .acceleration(&dq, &dqd, Dual64::from(0.0))
                .expect("M is positive definite");
            let exact = a.map(|x| x.eps);
            duals = duals.max(error(&column, &exact));
        }
        // The runtime's dense solve of the same tangent systems.
        let motion =
            constrained::__private::Generated::<f64, 8, 0>::gauss(&system, &q, &qd, 0.0, None)
                .expect("the motion exists");
        let reference = constrained::linearize::acceleration_jacobian::<f64, _, 8, 0, 0, 16>(
            &system, &q, &qd, 0.0, motion,
        );
        let scale = reference.dq.amax().max(reference.dqd.amax()).max(1.0);
        dense = dense.max(
            (jac.dq - reference.dq)
                .amax()
                .max((jac.dqd - reference.dqd).amax())
                / scale,
        );
    }
    println!("8-link pendulum (directional): central differences {central:.1e}, dual numbers {duals:.1e}, dense {dense:.1e}");
    // The chain's accelerations are large and steep: h = 1e-6 leaves ~1e-6 of
    // truncation error; the dual numbers are the tight check.
    assert!(central < 1e-5, "{central:e} against central differences");
    assert!(duals < 1e-12, "{duals:e} against dual numbers");
    assert!(dense < 1e-12, "{dense:e} against the dense solve");
}
