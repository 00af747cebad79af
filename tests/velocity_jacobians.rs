//! The Jacobians of `q̈` and `λ` where `gauss` solves the quaternions'
//! velocity form: the tangent systems solved through its own factors
//! (`emit/mass_inverse/factored/velocity_jacobian.rs`), the legs' solve
//! on the quadruped and the saddle-point `L D Lᵀ` on a pinned free body,
//! on a trunk whose ball-jointed foot is held at a point and on a free
//! block welded by a point and an orientation lock (rows in the world's
//! axes). Against two
//! independent truths, at moving states off the constraint surface (and,
//! for the trunk, off the quaternions' unit spheres): the runtime's dense
//! solve of the same tangent systems (the auxiliary mass's Cholesky factor
//! and `S`'s `L D Lᵀ`), and central differences of `q̈` and `λ`. A leg
//! stretched straight fails the legs' pivot test: the runtime's dense
//! solve answers there, the same numbers as called directly.

use crate::contacts::PinnedTop;
use crate::quadruped::model::Quadruped;
use crate::quadruped::{perturbed, standing};
use crate::rotations::Welded;
use crate::spherical::FootOnOnePoint;
use constrained::linearize::{try_acceleration_and_multiplier_jacobians, MultiplierJacobians};
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{SMatrix, SVector, UnitQuaternion};
use constrained::{ConstrainedSystem, Jacobians, State};

/// The largest entry of `a − b` against the largest of `b` (at least 1).
fn gap<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    (a - b).iter().fold(0.0f64, |m, x| m.max(x.abs())) / scale
}

/// The worst differences over a test's states from the dense solve and
/// from central differences, and how many states the generated solve
/// answered itself (its answer not bitwise the dense one).
#[derive(Default)]
struct Gaps {
    dense: f64,
    central: f64,
    own: usize,
}

/// Both Jacobians, of `q̈` and of `λ`.
type Both<const N_: usize, const K: usize, const NU: usize> =
    (Jacobians<f64, N_, NU>, MultiplierJacobians<f64, N_, K, NU>);

impl Gaps {
    /// One state's [`compare!`].
    fn add<const N_: usize, const K: usize, const NU: usize>(
        &mut self,
        (generated, dense, central): (Both<N_, K, NU>, Both<N_, K, NU>, f64),
    ) {
        self.dense = self.dense.max(worst(&generated, &dense));
        self.central = self.central.max(central);
        self.own += usize::from(generated != dense);
    }

    /// Prints them under `name`, then asserts: within 1e-11 of the dense
    /// solve and 1e-6 of central differences, and all `states` answered
    /// by `solve` itself.
    fn check(&self, name: &str, states: usize, solve: &str) {
        let (dense, central) = (self.dense, self.central);
        println!("{name}: dense {dense:.1e}, central differences {central:.1e}");
        assert_eq!(self.own, states, "{solve} answered every state itself");
        assert!(dense < 1e-11, "{dense:e} from the dense solve");
        assert!(central < 1e-6, "{central:e} from central differences");
    }
}

/// The worst of the three blocks of `q̈`'s and of `λ`'s Jacobians.
fn worst<const N_: usize, const K: usize, const NU: usize>(
    (a, l): &(Jacobians<f64, N_, NU>, MultiplierJacobians<f64, N_, K, NU>),
    (b, m): &(Jacobians<f64, N_, NU>, MultiplierJacobians<f64, N_, K, NU>),
) -> f64 {
    [
        gap(&a.dq, &b.dq),
        gap(&a.dqd, &b.dqd),
        gap(&a.du, &b.du),
        gap(&l.dq, &m.dq),
        gap(&l.dqd, &m.dqd),
        gap(&l.du, &m.du),
    ]
    .into_iter()
    .fold(0.0, f64::max)
}

/// `(generated, dense, central differences by q and q̇)` for one state:
/// the generated pair, the runtime's dense pair, and the worst gap of the
/// generated `∂q̈/∂q`, `∂q̈/∂q̇`, `∂λ/∂q`, `∂λ/∂q̇` from central differences.
macro_rules! compare {
    ($sys:expr, $s:expr, $n:literal, $k:literal, $nu:literal) => {{
        let (sys, s): (&_, &State<f64, $n>) = ($sys, $s);
        let generated = sys
            .acceleration_and_multiplier_jacobians(&s.q, &s.qd, s.t)
            .expect("generated Jacobians");
        let qdd = ConstrainedSystem::<f64, $n, $k>::acceleration(sys, s).expect("q̈");
        let force = sys.constraint_force(&s.q, &s.qd, s.t).expect("Fᶜ");
        let dense =
            try_acceleration_and_multiplier_jacobians::<_, _, $n, $k, $nu, { 2 * $n + $nu }>(
                sys,
                &s.q,
                &s.qd,
                s.t,
                (qdd, force),
            )
            .expect("dense Jacobians");
        let answer = |q: &SVector<f64, $n>, qd: &SVector<f64, $n>| {
            let x = State::new(s.t, *q, *qd);
            let a = ConstrainedSystem::<f64, $n, $k>::acceleration(sys, &x).expect("q̈");
            let l = Multipliers::<f64, $n, $k>::constraint_multipliers(sys, &x).expect("λ");
            (a, l)
        };
        let mut central = 0.0f64;
        for c in 0..$n {
            for by_velocity in [false, true] {
                let (mut plus, mut minus) = (s.q, s.q);
                let (mut vplus, mut vminus) = (s.qd, s.qd);
                let h = 1e-6;
                if by_velocity {
                    vplus[c] += h;
                    vminus[c] -= h;
                } else {
                    plus[c] += h;
                    minus[c] -= h;
                }
                let (ap, lp) = answer(&plus, &vplus);
                let (am, lm) = answer(&minus, &vminus);
                let (da, dl) = ((ap - am) / (2.0 * h), (lp - lm) / (2.0 * h));
                let (ja, jl) = if by_velocity {
                    (generated.0.dqd.column(c), generated.1.dqd.column(c))
                } else {
                    (generated.0.dq.column(c), generated.1.dq.column(c))
                };
                let scale_a = generated.0.dq.amax().max(generated.0.dqd.amax()).max(1.0);
                let scale_l = generated.1.dq.amax().max(generated.1.dqd.amax()).max(1.0);
                central = central
                    .max((ja - da).amax() / scale_a)
                    .max((jl - dl).amax() / scale_l);
            }
        }
        (generated, dense, central)
    }};
}

/// The quadruped, the legs' solve, at 8 tumbling states off the
/// constraint surface with torques on: the generated Jacobians equal the
/// runtime's dense ones to 1e-11 and central differences to 1e-6.
#[test]
fn the_legs_solve_gives_the_dense_jacobians() {
    let (feet, rest) = standing(0.7);
    let [a, b, c, d, e, f, g, h] = feet;
    let t = |i: u32| 0.4 * f64::from(i).sin();
    let sys = Quadruped::new(
        a,
        b,
        c,
        d,
        e,
        f,
        g,
        h,
        t(1),
        t(2),
        t(3),
        t(4),
        t(5),
        t(6),
        t(7),
        t(8),
        t(9),
        t(10),
        t(11),
        t(12),
    );
    let mut gaps = Gaps::default();
    for k in 0..8 {
        gaps.add(compare!(&sys, &perturbed(&rest, k), 19, 13, 12));
    }
    gaps.check("quadruped", 8, "the legs' solve");
    // A front leg straight: its `det J` fails the pivot test, and the
    // runtime's dense solve answers, exactly as called directly.
    let mut s = perturbed(&rest, 3);
    s.q[8] = 0.0;
    s.q[9] = 0.0;
    let (generated, dense, _) = compare!(&sys, &s, 19, 13, 12);
    assert_eq!(generated, dense, "a straight leg: the dense solve's answer");
}

/// The pinned free body (one quaternion, a point's three rows in its own
/// axes, the saddle-point `L D Lᵀ`) and the trunk on a ball-jointed foot
/// (two quaternions), at 8 moving states each, the trunk's half off the
/// unit spheres: the generated Jacobians equal the dense ones to 1e-11 and
/// central differences to 1e-6.
#[test]
fn the_saddle_point_solve_gives_the_dense_jacobians() {
    let top = PinnedTop::<f64>::new(0.8, 0.3, 2.0, 0.4);
    let trunk = FootOnOnePoint::<f64>::new(0.1, -0.05, 0.2);
    let mut gaps = Gaps::default();
    for k in 0..8 {
        let x = f64::from(k);
        let e = UnitQuaternion::from_euler_angles(0.3 * x.sin(), -0.4, 0.2 * x);
        let mut q = SVector::<f64, 7>::zeros();
        q[0] = 0.01 * x;
        for (i, v) in [e.w, e.i, e.j, e.k].into_iter().enumerate() {
            q[3 + i] = v;
        }
        let qd = SVector::<f64, 7>::from_fn(|i, _| (0.9 * (i as f64 + x)).cos());
        gaps.add(compare!(&top, &State::new(0.0, q, qd), 7, 4, 0));
        let s = crate::common::trunk_on_foot_state(k);
        gaps.add(compare!(&trunk, &s, 11, 5, 0));
    }
    gaps.check("pinned top and trunk", 16, "the saddle-point solve");
}

/// An orientation lock, whose rows stay in the world's axes (`D` the
/// identity there): a free block welded to the world by a point and a
/// lock, at 8 moving states off the lock and off the unit sphere: the
/// generated Jacobians equal the dense ones to 1e-11 and central
/// differences to 1e-6.
#[test]
fn an_orientation_lock_gives_the_dense_jacobians() {
    let welded = Welded::<f64>::new(0.3, -0.2, 0.5);
    let mut gaps = Gaps::default();
    for k in 0..8 {
        let x = f64::from(k);
        let e = UnitQuaternion::from_euler_angles(0.3 + 0.1 * x.sin(), -0.2, 0.5 + 0.05 * x);
        let scale = 1.0 + 0.04 * (x - 3.5);
        let mut q = SVector::<f64, 7>::zeros();
        q[0] = 0.01 * x;
        for (i, v) in [e.w, e.i, e.j, e.k].into_iter().enumerate() {
            q[3 + i] = scale * v;
        }
        let qd = SVector::<f64, 7>::from_fn(|i, _| 0.5 * (0.9 * (i as f64 + x)).cos());
        gaps.add(compare!(&welded, &State::new(0.0, q, qd), 7, 7, 0));
    }
    gaps.check("orientation lock", 8, "the saddle-point solve");
}
