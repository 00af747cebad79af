//! The evaluations reached generically, through `ConstrainedSystem`:
//! `kinetic_energy`, `potential_energy`, `energy` (systems given by
//! energies or bodies) and `gravity_forces` (bodies), each `None` where
//! the system lacks it. Checked against closed forms, against the finite
//! differences of the potential, and through a generic energy-drift
//! check over an integration; a value that overflows is `Err(NonFinite)`.

use constrained::models::{CartPole, CartPoleCartesian, DoublePendulumAngles};
use constrained::nalgebra::SVector;
use constrained::{constrained_system, ConstrainedSystem, DormandPrince45, DynamicsError, State};

constrained_system! {
    /// A unit mass on a spring of stiffness 4: `M = 1` is constant, so its
    /// inherent methods are total (plain values).
    pub struct Spring {
        coordinates: [x],
        kinetic_energy: dot(x).powi(2) / 2.0,
        potential_energy: 2.0 * x.powi(2),
    }
}

constrained_system! {
    /// The same spring with a damper: its energy decays.
    pub struct DampedSpring {
        coordinates: [x],
        kinetic_energy: dot(x).powi(2) / 2.0,
        potential_energy: 2.0 * x.powi(2),
        forces: [-0.5 * dot(x)],
    }
}

constrained_system! {
    /// A rigid pendulum as one body: mass 2 with its centre 0.7 from a
    /// joint turning about y, gravity 9.81 along −z.
    pub struct PendulumBody {
        gravity: [0.0, 0.0, -9.81],
        bodies: [rod {
            joint: revolute(th, [0.0, 1.0, 0.0]),
            mass: 2.0,
            com: [0.0, 0.0, -0.7],
            inertia: diag[0.01, 0.02, 0.01],
        }],
    }
}

/// The four evaluations of any system, through the trait alone.
#[allow(clippy::type_complexity)]
fn evaluations<S, const N: usize, const K: usize>(
    system: &S,
    state: &State<f64, N>,
) -> [Option<Result<f64, DynamicsError>>; 3]
where
    S: ConstrainedSystem<f64, N, K>,
{
    [
        ConstrainedSystem::kinetic_energy(system, state),
        ConstrainedSystem::potential_energy(system, state),
        ConstrainedSystem::energy(system, state),
    ]
}

fn close(value: Option<Result<f64, DynamicsError>>, expected: f64) {
    match value {
        Some(Ok(v)) => assert!(
            (v - expected).abs() <= 1e-12 * expected.abs().max(1.0),
            "{v} vs {expected}"
        ),
        other => panic!("{other:?}, expected {expected}"),
    }
}

#[test]
fn cart_pole_energies_are_the_closed_forms() {
    let (mc, mp, l, g) = (1.3, 0.4, 0.8, 9.81);
    let system = CartPole::new(mc, mp, l, g, 0.0);
    for (s, th, sd, thd) in [(0.2f64, 0.7f64, -1.1, 2.3), (-1.0, 3.0, 0.5, -0.4)] {
        let state = State::new(0.0, SVector::from([s, th]), SVector::from([sd, thd]));
        // The tip at (s + l sin θ, −l cos θ).
        let (vx, vy) = (sd + l * th.cos() * thd, l * th.sin() * thd);
        let kinetic = mc * sd * sd / 2.0 + mp * (vx * vx + vy * vy) / 2.0;
        let potential = -mp * g * l * th.cos();
        let [t, v, e] = evaluations(&system, &state);
        close(t, kinetic);
        close(v, potential);
        close(e, kinetic + potential);
        assert_eq!(ConstrainedSystem::gravity_forces(&system, &state), None);
    }
}

#[test]
fn a_total_system_forwards_its_plain_energies_as_ok() {
    let state = State::new(0.0, SVector::from([0.3]), SVector::from([-1.5]));
    let [t, v, e] = evaluations(&Spring::new(), &state);
    close(t, 1.5 * 1.5 / 2.0);
    close(v, 2.0 * 0.3 * 0.3);
    close(e, 1.125 + 0.18);
}

#[test]
fn a_system_given_by_its_mass_has_no_energy() {
    let system = CartPoleCartesian::new(1.0, 0.5, 0.8, 9.81, 0.0);
    let state = State::new(0.0, SVector::from([0.0, 0.0, -0.8]), SVector::zeros());
    assert_eq!(evaluations(&system, &state), [None, None, None]);
    assert_eq!(ConstrainedSystem::gravity_forces(&system, &state), None);
}

#[test]
fn gravity_of_a_body_is_the_gradient_of_its_potential() {
    let (m, c, g) = (2.0, 0.7, 9.81);
    let system = PendulumBody::new();
    for th in [0.0f64, 0.4, -2.1, 3.0] {
        let at = |th: f64| State::new(0.0, SVector::from([th]), SVector::from([0.9]));
        let gravity = match ConstrainedSystem::gravity_forces(&system, &at(th)) {
            Some(Ok(v)) => v[0],
            other => panic!("{other:?}"),
        };
        // The centre (0, 0, −c) turned by θ about y: (−c sin θ, 0, −c cos θ).
        let closed = m * g * c * th.sin();
        assert!((gravity - closed).abs() < 1e-12, "{gravity} vs {closed}");
        let potential = |th: f64| match ConstrainedSystem::potential_energy(&system, &at(th)) {
            Some(Ok(v)) => v,
            other => panic!("{other:?}"),
        };
        close(Some(Ok(potential(th))), -m * g * c * th.cos());
        let h = 1e-6;
        let difference = (potential(th + h) - potential(th - h)) / (2.0 * h);
        assert!(
            (gravity - difference).abs() < 1e-7,
            "{gravity} vs {difference}"
        );
    }
}

/// The relative drift of the energy over a run, for any system that has
/// an energy: the generic check the trait's `energy` makes possible.
fn energy_drift<S, const N: usize, const K: usize>(system: &S, mut state: State<f64, N>) -> f64
where
    S: ConstrainedSystem<f64, N, K>,
{
    let energy = |s: &State<f64, N>| match system.energy(s) {
        Some(Ok(e)) => e,
        other => panic!("{other:?}"),
    };
    let before = energy(&state);
    DormandPrince45::new(1e-11, 1e-12)
        .advance(system, &mut state, 2.0)
        .unwrap();
    (energy(&state) - before).abs() / before.abs().max(1.0)
}

#[test]
fn energy_is_conserved_by_a_generic_check() {
    let pendulum = DoublePendulumAngles::new(1.0, 0.5, 1.0, 0.7, 9.81);
    let state = State::new(0.0, SVector::from([1.0, -0.5]), SVector::from([0.3, 2.0]));
    assert!(energy_drift(&pendulum, state) < 1e-8);
    let body = State::new(0.0, SVector::from([2.5]), SVector::from([1.0]));
    assert!(energy_drift(&PendulumBody::new(), body) < 1e-8);
    let spring = State::new(0.0, SVector::from([1.0]), SVector::zeros());
    assert!(energy_drift(&Spring::new(), spring) < 1e-8);
    // The check can fail: a damped spring loses energy.
    assert!(energy_drift(&DampedSpring::new(), spring) > 0.1);
}

#[test]
fn an_energy_that_overflows_is_an_error() {
    let state = State::new(0.0, SVector::from([0.0, 0.1]), SVector::from([1e200, 0.0]));
    let system = CartPole::new(1.0, 0.4, 0.8, 9.81, 0.0);
    let [t, _, e] = evaluations(&system, &state);
    assert_eq!(t, Some(Err(DynamicsError::NonFinite)));
    assert_eq!(e, Some(Err(DynamicsError::NonFinite)));
    let spring = State::new(0.0, SVector::from([1e200]), SVector::zeros());
    let [_, v, _] = evaluations(&Spring::new(), &spring);
    assert_eq!(v, Some(Err(DynamicsError::NonFinite)));
}
