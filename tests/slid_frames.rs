//! The dynamics' frames slid along their joints' axes
//! (`codegen/src/bodies/slide.rs`), against the same arm described with
//! its frames already where the slides put them, written here by hand:
//! `M`, `τ` and the acceleration agree, the derivation prints the slides
//! of the one and none of the other.

use constrained::constrained_system;
use constrained::nalgebra::Vector2;

constrained_system! {
    /// An arm about `z` on a post, its forearm about `x` at
    /// `[0.1, 0, 0.3]`: offsets along both axes, which slides empty.
    pub struct AsDescribed {
        inputs: [u1, u2],
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            upper {
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.5],
                mass: 1.0,
                com: [0.1, 0.02, 0.03],
                inertia: diag[0.01, 0.02, 0.03],
            },
            fore {
                parent: upper,
                joint: revolute(q2, [1.0, 0.0, 0.0]),
                xyz: [0.1, 0.0, 0.3],
                mass: 0.5,
                com: [0.02, 0.1, 0.01],
                inertia: diag[0.004, 0.005, 0.006],
            },
        ],
        forces: [u1, u2],
    }
}

constrained_system! {
    /// The same arm with the upper frame 0.3 up its axis (the post 0.8,
    /// the forearm's joint 0.3 lower in it, the centre 0.3 lower) and the
    /// forearm's frame 0.1 back along `x` (its joint at the upper origin,
    /// its centre 0.1 further out): nothing left for a slide to empty.
    pub struct SlidByHand {
        inputs: [u1, u2],
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            upper {
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.8],
                mass: 1.0,
                com: [0.1, 0.02, -0.27],
                inertia: diag[0.01, 0.02, 0.03],
            },
            fore {
                parent: upper,
                joint: revolute(q2, [1.0, 0.0, 0.0]),
                xyz: [0.0, 0.0, 0.0],
                mass: 0.5,
                com: [0.12, 0.1, 0.01],
                inertia: diag[0.004, 0.005, 0.006],
            },
        ],
        forces: [u1, u2],
    }
}

#[test]
fn slid_frames_keep_the_dynamics_and_are_printed() {
    let described = AsDescribed::<f64>::DERIVATION;
    assert!(
        described.contains("its frame slid by 3/10 along the axis")
            && described.contains("its frame slid by −1/10 along the axis"),
        "{described}"
    );
    assert!(!SlidByHand::<f64>::DERIVATION.contains("slid by"));
    let (a, b) = (AsDescribed::new(0.7, -1.3), SlidByHand::new(0.7, -1.3));
    for k in 0..8 {
        let x = k as f64;
        let q = Vector2::new(0.3 + 0.7 * x, -1.1 + 0.4 * x);
        let qd = Vector2::new(1.2 - 0.3 * x, 0.5 + 0.2 * x);
        let qdd = Vector2::new(-0.4 + 0.1 * x, 2.0 - 0.5 * x);
        let (ma, mb) = (a.mass_matrix(&q, 0.0), b.mass_matrix(&q, 0.0));
        assert_close(ma.as_slice(), mb.as_slice());
        let ta = a.inverse_dynamics(&q, &qd, &qdd, 0.0).expect("finite");
        let tb = b.inverse_dynamics(&q, &qd, &qdd, 0.0).expect("finite");
        assert_close(ta.as_slice(), tb.as_slice());
        let qa = a.acceleration(&q, &qd, 0.0).expect("regular");
        let qb = b.acceleration(&q, &qd, 0.0).expect("regular");
        assert_close(qa.as_slice(), qb.as_slice());
    }
}

/// Each entry of `a` within 1e-14 of `b`'s (relative, absolute below 1).
fn assert_close(a: &[f64], b: &[f64]) {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-14 * x.abs().max(1.0);
    assert!(
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| close(*x, *y)),
        "{a:?} {b:?}"
    );
}
