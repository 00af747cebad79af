//! Lagrange's equations from energies (`kinetic_energy`, `potential_energy`,
//! `dt`), against textbook equations written by hand and against the same
//! systems in Cartesian form.

use constrained::models::{double_pendulum_state, CartPole, DoublePendulum, DoublePendulumAngles};
use constrained::nalgebra::{SVector, Vector2};
use constrained::{constrained_system, DormandPrince45, State};

/// The textbook cart-pole: `M = [[mc + mp, mp l cos θ], [mp l cos θ, mp l²]]`,
/// `F = [u + mp l θ̇² sin θ, −mp g l sin θ]`.
fn textbook(p: [f64; 5], th: f64, thd: f64) -> ([[f64; 2]; 2], [f64; 2]) {
    let [mc, mp, l, g, u] = p;
    let (s, c) = th.sin_cos();
    (
        [[mc + mp, mp * l * c], [mp * l * c, mp * l * l]],
        [u + mp * l * thd * thd * s, -mp * g * l * s],
    )
}

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

#[test]
fn cart_pole_mass_and_forces_are_the_textbook_ones() {
    let mut rng = Rng(7);
    for _ in 0..200 {
        let p = [0.5, 1.5, 0.5, 1.0, -2.0].map(|lo: f64| lo + rng.uniform(0.1, 2.0));
        let system = CartPole::new(p[0], p[1], p[2], p[3], p[4]);
        let q = Vector2::new(rng.uniform(-2.0, 2.0), rng.uniform(-4.0, 4.0));
        let qd = Vector2::new(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
        let (m, f) = textbook(p, q[1], qd[1]);
        let mass = system.mass_matrix(&q, 0.0);
        let forces = system.forces(&q, &qd, 0.0);
        for i in 0..2 {
            assert!(
                (forces[i] - f[i]).abs() < 1e-12 * (1.0 + f[i].abs()),
                "F{i}: {} vs {}",
                forces[i],
                f[i]
            );
            for j in 0..2 {
                assert!((mass[(i, j)] - m[i][j]).abs() < 1e-12, "M{i}{j}");
            }
        }
    }
}

/// Integrated side by side for 3 s, the angle model and the Cartesian model
/// (four coordinates, two rod constraints) stay together.
#[test]
fn double_pendulum_from_energies_follows_the_cartesian_model() {
    let (m1, m2, l1, l2, g) = (1.0, 0.7, 1.2, 0.9, 9.81);
    let angles = DoublePendulumAngles::new(m1, m2, l1, l2, g);
    let cartesian = DoublePendulum::new(m1, m2, l1, l2, g);
    let (th, thd) = ([1.1, -0.4], [0.3, 1.7]);
    let mut a = State::new(0.0, Vector2::from(th), Vector2::from(thd));
    let mut c = double_pendulum_state(l1, l2, 0.0, th, thd);
    let method = DormandPrince45::new(1e-11, 1e-12);
    let mut worst: f64 = 0.0;
    for k in 1..=30 {
        let t = 0.1 * k as f64;
        method
            .advance(&angles, &mut a, t)
            .expect("angles integrate");
        method
            .advance(&cartesian, &mut c, t)
            .expect("cartesian integrates");
        let from_angles = double_pendulum_state(l1, l2, t, [a.q[0], a.q[1]], [a.qd[0], a.qd[1]]);
        worst = worst
            .max((from_angles.q - c.q).amax())
            .max((from_angles.qd - c.qd).amax());
    }
    println!("angles vs Cartesian over 3 s: largest difference {worst:.1e}");
    assert!(worst < 1e-7, "largest difference {worst:e}");
}

constrained_system! {
    /// A point mass in the plane from `T = m (ẋ² + ẏ²)/2` with a literal
    /// mass: M is a positive-definite constant, so `acceleration` returns a
    /// plain vector, as for `mass: diag[2.0, 2.0]`.
    pub struct ProjectileFromEnergy {
        coordinates: [x, y],
        kinetic_energy: 2.0 * (dot(x).powi(2) + dot(y).powi(2)) / 2.0,
        potential_energy: 2.0 * 9.81 * y,
        constraints: [y == x.powi(2)],
    }
}

#[test]
fn constant_derived_mass_takes_the_constant_mass_path() {
    let system = ProjectileFromEnergy::default();
    let q = Vector2::new(0.5, 0.25);
    let qd = Vector2::new(1.0, 1.0);
    // A plain SVector, not a Result: the compile-time specialisation.
    let qdd: SVector<f64, 2> = system.acceleration(&q, &qd, 0.0);
    // On the parabola y = x²: ÿ = 2ẋ² + 2xẍ, and q̈ + g ŷ is along the normal (−2x, 1).
    assert!((qdd[1] - (2.0 + 2.0 * 0.5 * qdd[0])).abs() < 1e-12);
    let lambda_direction = Vector2::new(qdd[0], qdd[1] + 9.81);
    assert!((lambda_direction[0] * 1.0 + lambda_direction[1] * 2.0 * 0.5).abs() < 1e-12);
}

constrained_system! {
    /// A pendulum whose support moves as `a sin ωt`: T depends on time
    /// explicitly through `dt` of the support's position.
    pub struct ShakenPendulum {
        coordinates: [th],
        parameters: [m, l, g, a, w],
        definitions: [xp = a * (w * t).sin() + l * th.sin(), yp = -l * th.cos()],
        kinetic_energy: m * (dt(xp).powi(2) + dt(yp).powi(2)) / 2.0,
        potential_energy: m * g * yp,
    }
}

/// `θ̈ = −(g/l) sin θ + (a ω²/l) sin ωt cos θ`.
#[test]
fn shaken_pendulum_has_the_textbook_acceleration() {
    let (m, l, g, a, w) = (0.3, 0.8, 9.81, 0.05, 7.0);
    let system = ShakenPendulum::new(m, l, g, a, w);
    let mut rng = Rng(11);
    for _ in 0..100 {
        let (th, thd, t) = (
            rng.uniform(-3.0, 3.0),
            rng.uniform(-2.0, 2.0),
            rng.uniform(0.0, 5.0),
        );
        let qdd = system
            .acceleration(&SVector::from([th]), &SVector::from([thd]), t)
            .expect("positive mass");
        let expected = -(g / l) * th.sin() + a * w * w / l * (w * t).sin() * th.cos();
        assert!(
            (qdd[0] - expected).abs() < 1e-12,
            "{} vs {expected}",
            qdd[0]
        );
    }
}

constrained_system! {
    /// A massless coordinate slaved to a massive one: `M = diag(1, 0)` is
    /// singular, the constraint `y = x²` completes it.
    pub struct MasslessFollower {
        coordinates: [x, y],
        parameters: [fx, fy],
        mass: diag[1.0, 0.0],
        forces: [fx, fy],
        constraints: [y == x.powi(2)],
    }
}

/// Row y of `M q̈ = F + Aᵀλ` reads `0 = fy + λ`, so `λ = −fy` and
/// `ẍ = fx + 2x fy`; `ÿ = 2ẋ² + 2xẍ` from the constraint.
#[test]
fn singular_constant_mass_completed_by_a_constraint() {
    let system = MasslessFollower::new(0.7, -1.3);
    let mut rng = Rng(5);
    for _ in 0..100 {
        let (x, xd) = (rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0));
        let q = Vector2::new(x, x * x);
        let qd = Vector2::new(xd, 2.0 * x * xd);
        let xdd = 0.7 + 2.0 * x * -1.3;
        let expected = Vector2::new(xdd, 2.0 * xd * xd + 2.0 * x * xdd);
        for (name, qdd) in [
            (
                "generalized inverse",
                system.acceleration(&q, &qd, 0.0).unwrap(),
            ),
            (
                "Moore–Penrose",
                system.acceleration_moore_penrose(&q, &qd, 0.0).unwrap(),
            ),
            (
                "Gibbs–Appell",
                system.acceleration_gibbs_appell(&q, &qd, 0.0).unwrap(),
            ),
        ] {
            assert!(
                (qdd - expected).amax() < 1e-12 * (1.0 + expected.amax()),
                "{name}: {qdd} vs {expected}"
            );
        }
        let force = system.constraint_force(&q, &qd, 0.0).unwrap();
        assert!(
            (force - Vector2::new(-2.0 * x * 1.3, 1.3)).amax() < 1e-12,
            "{force}"
        );
    }
}

/// The four-bar in link angles (`M(q)` from energies, 2 loop closures,
/// factored in generated code) moves as the body-coordinate four-bar: on
/// the parallelogram branch its angle accelerations are the closed form's
/// `(θ̈, 0, θ̈)`, and near the branch point too.
#[test]
fn four_bar_in_link_angles_has_the_closed_form_motion() {
    use constrained::models::{
        four_bar_acceleration, ParallelogramFourBar, ParallelogramFourBarAngles,
    };
    use constrained::nalgebra::Vector3;
    let p = [1.2, 0.15, 1.0, 2.0, 9.81];
    let angles = ParallelogramFourBarAngles::<f64>::new(p[0], p[1], p[2], p[3], p[4]);
    let bodies = ParallelogramFourBar::<f64>::new(p[0], p[1], p[2], p[3], p[4]);
    let mut worst = 0.0f64;
    for theta in [1.2, 0.7, -0.4, 1e-2, 1e-4] {
        for omega in [0.0, 1.3, -2.0] {
            let q = Vector3::new(theta, 0.0, theta);
            let qd = Vector3::new(omega, 0.0, omega);
            let qdd = angles
                .acceleration(&q, &qd, 0.0)
                .expect("M is positive definite");
            let exact = four_bar_acceleration(&bodies, theta, omega);
            let want = Vector3::new(exact[2], exact[5], exact[8]);
            worst = worst.max((qdd - want).amax() / want.amax().max(1.0));
        }
    }
    println!("four-bar in link angles against the closed form: {worst:.1e}");
    assert!(worst < 1e-9, "{worst:e}");
}

/// `energy()` of an energy-form model along an unforced `DormandPrince45`
/// run: the largest relative change over `duration`.
fn energy_drift<S, const N: usize, const K: usize>(
    system: &S,
    mut state: State<f64, N>,
    energy: impl Fn(&S, &State<f64, N>) -> f64,
    duration: f64,
) -> f64
where
    S: constrained::ConstrainedSystem<f64, N, K>,
{
    let start = energy(system, &state);
    let mut worst = 0.0f64;
    let times: Vec<f64> = (1..=50).map(|i| duration * i as f64 / 50.0).collect();
    DormandPrince45::new(1e-11, 1e-13)
        .advance_sampled(system, &mut state, duration, &times, |s| {
            worst = worst.max((energy(system, s) - start).abs());
        })
        .expect("the run completes");
    worst / start.abs().max(1.0)
}

#[test]
fn cart_pole_energy_is_conserved() {
    let system = CartPole::new(1.0, 0.3, 0.5, 9.81, 0.0);
    let state = State::new(0.0, Vector2::new(0.1, 2.5), Vector2::new(0.4, -1.0));
    let drift = energy_drift(
        &system,
        state,
        |s, x| s.energy(&x.q, &x.qd, x.t).unwrap(),
        3.0,
    );
    assert!(drift < 1e-9, "{drift:e}");
}

#[test]
fn double_pendulum_angles_energy_is_conserved() {
    let system = DoublePendulumAngles::new(1.0, 0.7, 1.0, 0.8, 9.81);
    let state = State::new(0.0, Vector2::new(1.2, -0.4), Vector2::new(0.3, 1.1));
    let drift = energy_drift(
        &system,
        state,
        |s, x| s.energy(&x.q, &x.qd, x.t).unwrap(),
        3.0,
    );
    assert!(drift < 1e-9, "{drift:e}");
}

#[test]
fn rigid_body_quaternion_energy_is_conserved() {
    use constrained::models::{quaternion_state, RigidBodyQuaternion};
    use constrained::nalgebra::{Vector3, Vector4};
    let system = RigidBodyQuaternion::new(1.0, 2.0, 3.0);
    let state = quaternion_state(
        0.0,
        Vector4::new(1.0, 0.2, -0.1, 0.3),
        Vector3::new(0.5, 2.0, -0.3),
    );
    // Kinetic only, and the intermediate axis tumbles: a demanding run.
    let drift = energy_drift(
        &system,
        state,
        |s, x| s.energy(&x.q, &x.qd, x.t).unwrap(),
        5.0,
    );
    assert!(drift < 1e-8, "{drift:e}");
}

#[test]
fn heavy_top_energy_is_conserved() {
    use constrained::models::{quaternion_state, HeavyTop};
    use constrained::nalgebra::{Vector3, Vector4};
    let system = HeavyTop::new(1.0, 0.5, 1.0, 9.81, 0.3);
    let state = quaternion_state(
        0.0,
        Vector4::new(0.9, 0.3, 0.0, 0.1),
        Vector3::new(0.2, -0.1, 20.0),
    );
    let drift = energy_drift(
        &system,
        state,
        |s, x| s.energy(&x.q, &x.qd, x.t).unwrap(),
        2.0,
    );
    assert!(drift < 1e-8, "{drift:e}");
}

#[test]
fn energies_are_what_was_written() {
    // T and V of the cart-pole at a state, by hand.
    let (mc, mp, l, g): (f64, f64, f64, f64) = (1.0, 0.3, 0.5, 9.81);
    let system = CartPole::new(mc, mp, l, g, 0.0);
    let (s, th, sd, thd): (f64, f64, f64, f64) = (0.2, 0.7, -0.4, 1.3);
    let (q, qd) = (Vector2::new(s, th), Vector2::new(sd, thd));
    let (xd, yd) = (sd + l * th.cos() * thd, l * th.sin() * thd);
    let t = mc * sd * sd / 2.0 + mp * (xd * xd + yd * yd) / 2.0;
    let v = -mp * g * l * th.cos();
    assert!((system.kinetic_energy(&q, &qd, 0.0).unwrap() - t).abs() < 1e-14);
    assert!((system.potential_energy(&q, 0.0).unwrap() - v).abs() < 1e-14);
    assert!((system.energy(&q, &qd, 0.0).unwrap() - t - v).abs() < 1e-14);
}
