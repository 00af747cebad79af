//! Writes every reference model as JSON for the independent sympy suite
//! (`tests/sympy/`): the macro's `SYMBOLIC` expressions and constraint
//! levels, and numbers at consistent states — random states projected onto
//! the constraints by the runtime — for `A`, `b`, `q̈` of both equations of
//! motion and the constraint force.
//!
//! It also writes the generated linearizations of the input-driven models
//! (`acceleration_jacobian`, `linearize`, `linearize_reduced`) at random
//! and equilibrium states, which the suite compares with
//! `sympy.physics.mechanics` derivations of its own.
//!
//! `cargo run -p constrained-tests --example sympy_export [-- PATH]` (default:
//! `<target>/sympy/systems.json`)

use constrained::models::*;
use constrained::nalgebra::{SMatrix, SVector, Vector2, Vector3};
use constrained::stabilize::project;
use constrained::{ConstrainedSystem, ConstraintLevel, State, SymbolicSystem};
use serde_json::{json, Value};

/// Consistent states per system.
const STATES: usize = 12;

/// A small deterministic generator (SplitMix64), so that the export is the
/// same on every run.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn vector<const M: usize>(v: &SVector<f64, M>) -> Value {
    json!(v.as_slice())
}

fn matrix<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> Value {
    json!((0..R)
        .map(|i| m.row(i).iter().copied().collect::<Vec<f64>>())
        .collect::<Vec<_>>())
}

/// The generated linearizations of one model at one state: the Jacobians,
/// `(A, B)` and the reduced form, each in the export's JSON.
macro_rules! linearization {
    ($system:expr, $params:expr, $q:expr, $qd:expr, $t:expr) => {{
        let (system, q, qd, t) = (&$system, &$q, &$qd, $t);
        let jacobians = system.acceleration_jacobian(q, qd, t).expect("the Jacobians exist");
        let (a, b) = system.linearize(q, qd, t).expect("the linearization exists");
        let reduced = system.linearize_reduced(q, qd, t).expect("the reduced linearization exists");
        json!({
            "t": t,
            "q": vector(q),
            "qd": vector(qd),
            "params": $params,
            "dq": matrix(&jacobians.dq),
            "dqd": matrix(&jacobians.dqd),
            "du": matrix(&jacobians.du),
            "a": matrix(&a),
            "b": matrix(&b),
            "reduced": {
                "a": matrix(&reduced.a),
                "b": matrix(&reduced.b),
                "coordinates": reduced.coordinates,
                "speeds": reduced.speeds,
            },
        })
    }};
}

/// The input-driven models' linearizations, at random states and at their
/// equilibria: the cart-pole in both forms (upright, the pole's angle π) and
/// the Chaplygin sleigh (random states with the blade's constraint met, and
/// straight-line motion, a relative equilibrium).
fn linearizations(rng: &mut Rng) -> Value {
    let pi = std::f64::consts::PI;
    let mut cart_pole = Vec::new();
    let mut cartesian = Vec::new();
    for k in 0..STATES {
        let [mc, mp, l, g] = [(); 4].map(|_| rng.uniform(0.5, 1.5));
        let upright = k == 0;
        let push = if upright { 0.0 } else { rng.uniform(-2.0, 2.0) };
        let system = CartPole::new(mc, mp, l, g, push);
        let (q, qd) = if upright {
            (Vector2::new(0.3, pi), Vector2::zeros())
        } else {
            (
                Vector2::new(rng.uniform(-1.0, 1.0), rng.uniform(-pi, pi)),
                Vector2::new(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)),
            )
        };
        let t = rng.uniform(0.0, 1.0);
        cart_pole.push(linearization!(system, [mc, mp, l, g, push], q, qd, t));
        if upright {
            // The tip straight above the cart, at rest.
            let system = CartPoleCartesian::new(mc, mp, l, g, 0.0);
            let q = Vector3::new(0.3, 0.3, l);
            cartesian.push(linearization!(
                system,
                [mc, mp, l, g, 0.0],
                q,
                Vector3::zeros(),
                t
            ));
        }
    }
    let mut sleigh = Vec::new();
    for k in 0..STATES {
        let [m, inertia, a] = [(); 3].map(|_| rng.uniform(0.5, 1.5));
        let straight = k == 0;
        let torque = if straight {
            0.0
        } else {
            rng.uniform(-2.0, 2.0)
        };
        let system = ChaplyginSleigh::new(m, inertia, a, torque);
        // The contact point's speed along the blade and the spin fix a q̇
        // that meets the constraint; straight-line motion has no spin.
        let theta = rng.uniform(-1.0, 1.0);
        let speed = rng.uniform(0.5, 2.0);
        let omega = if straight {
            0.0
        } else {
            rng.uniform(-2.0, 2.0)
        };
        let q = Vector3::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), theta);
        let qd = Vector3::new(
            speed * theta.cos() - a * theta.sin() * omega,
            speed * theta.sin() + a * theta.cos() * omega,
            omega,
        );
        let t = rng.uniform(0.0, 1.0);
        sleigh.push(linearization!(system, [m, inertia, a, torque], q, qd, t));
    }
    json!([
        { "name": "CartPole", "states": cart_pole },
        { "name": "CartPoleCartesian", "states": cartesian },
        { "name": "ChaplyginSleigh", "states": sleigh },
    ])
}

fn export<S, const N: usize, const K: usize>(
    symbolic: SymbolicSystem,
    make: impl Fn(&[f64]) -> S,
    rng: &mut Rng,
) -> Value
where
    S: ConstrainedSystem<f64, N, K>,
{
    let mut states = Vec::new();
    let mut attempts = 0;
    while states.len() < STATES && attempts < 50 * STATES {
        attempts += 1;
        // Parameters, then inputs: the constructor's order.
        let params: Vec<f64> = symbolic
            .parameters
            .iter()
            .chain(symbolic.inputs)
            .map(|_| rng.uniform(0.5, 1.5))
            .collect();
        let system = make(&params);
        let mut state = State::new(
            rng.uniform(0.0, 1.0),
            SVector::<f64, N>::from_fn(|_, _| rng.uniform(-1.0, 1.0)),
            SVector::<f64, N>::from_fn(|_, _| rng.uniform(-1.0, 1.0)),
        );
        if project(&system, &mut state, 1e-13, 50).is_err() {
            continue;
        }
        let (Ok(qdd), Ok(force)) = (system.acceleration(&state), system.constraint_force(&state))
        else {
            continue;
        };
        let (a, b) = system.constraint_matrices(&state);
        let rows: Vec<Value> = (0..K)
            .map(|i| json!(a.row(i).iter().copied().collect::<Vec<f64>>()))
            .collect();
        let gibbs_appell = system.acceleration_gibbs_appell(&state).ok();
        states.push(json!({
            "t": state.t,
            "q": vector(&state.q),
            "qd": vector(&state.qd),
            "params": params,
            "residual": vector(&system.constraint_residual(&state)),
            "a": rows,
            "b": vector(&b),
            "qdd": vector(&qdd),
            "qdd_gibbs_appell": gibbs_appell.as_ref().map(vector),
            "constraint_force": vector(&force),
        }));
    }
    assert_eq!(
        states.len(),
        STATES,
        "{}: consistent states are hard to find",
        symbolic.name
    );
    let levels: Vec<&str> = S::CONSTRAINT_LEVELS
        .iter()
        .map(|l| match l {
            ConstraintLevel::Position => "position",
            ConstraintLevel::Velocity => "velocity",
        })
        .collect();
    json!({
        "name": symbolic.name,
        "coordinates": symbolic.coordinates,
        // Every symbol with a value in `params`: the inputs are the last.
        "parameters": symbolic.parameters.iter().chain(symbolic.inputs).collect::<Vec<_>>(),
        "inputs": symbolic.inputs,
        "mass": symbolic.mass,
        "forces": symbolic.forces,
        "constraints": symbolic.constraints,
        "a_matrix": symbolic.a_matrix,
        "b_vector": symbolic.b_vector,
        "definitions": symbolic.definitions,
        "energies": symbolic.energies.map(|e| json!({
            "kinetic": e.kinetic,
            "potential": e.potential,
            "generalized_forces": e.generalized_forces,
        })),
        "levels": levels,
        "states": states,
    })
}

fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        // Under cargo's target directory (CARGO_TARGET_DIR when set).
        let target = std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into());
        format!("{target}/sympy/systems.json")
    });
    let mut rng = Rng(0x5eed_5e1f);
    let systems = vec![
        export(
            Appell::<f64>::SYMBOLIC,
            |p| Appell::new(p[0], p[1]),
            &mut rng,
        ),
        export(
            AppellTimeDependent::<f64>::SYMBOLIC,
            |p| AppellTimeDependent::new(p[0], p[1]),
            &mut rng,
        ),
        export(
            SphericalPendulum::<f64>::SYMBOLIC,
            |p| SphericalPendulum::new(p[0], p[1], p[2]),
            &mut rng,
        ),
        export(
            DoublePendulum::<f64>::SYMBOLIC,
            |p| DoublePendulum::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            RedundantDoublePendulum::<f64>::SYMBOLIC,
            |p| RedundantDoublePendulum::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            BeadOnRotatingHoop::<f64>::SYMBOLIC,
            |p| BeadOnRotatingHoop::new(p[0], p[1], p[2], p[3]),
            &mut rng,
        ),
        export(
            ChaplyginSleigh::<f64>::SYMBOLIC,
            |p| ChaplyginSleigh::new(p[0], p[1], p[2], p[3]),
            &mut rng,
        ),
        export(
            SliderCrank::<f64>::SYMBOLIC,
            |p| SliderCrank::new(p[0], p[1], p[2], p[3], p[4], p[5]),
            &mut rng,
        ),
        export(
            ParallelogramFourBar::<f64>::SYMBOLIC,
            |p| ParallelogramFourBar::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            ParallelogramFourBarAngles::<f64>::SYMBOLIC,
            |p| ParallelogramFourBarAngles::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            Crane::<f64>::SYMBOLIC,
            |p| Crane::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]),
            &mut rng,
        ),
        export(
            CartPole::<f64>::SYMBOLIC,
            |p| CartPole::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            CartPoleCartesian::<f64>::SYMBOLIC,
            |p| CartPoleCartesian::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            DoublePendulumAngles::<f64>::SYMBOLIC,
            |p| DoublePendulumAngles::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            RigidBodyQuaternion::<f64>::SYMBOLIC,
            |p| RigidBodyQuaternion::new(p[0], p[1], p[2]),
            &mut rng,
        ),
        export(
            HeavyTop::<f64>::SYMBOLIC,
            |p| HeavyTop::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            RollingDisk::<f64>::SYMBOLIC,
            |p| RollingDisk::new(p[0], p[1], p[2], p[3], p[4]),
            &mut rng,
        ),
        export(
            TwoLinkArmOnLine::<f64>::SYMBOLIC,
            |p| TwoLinkArmOnLine::new(p[0], p[1], p[2], p[3], p[4], p[5]),
            &mut rng,
        ),
    ];
    if let Some(dir) = std::path::Path::new(&path).parent() {
        std::fs::create_dir_all(dir).expect("the output folder can be made");
    }
    let linearizations = linearizations(&mut rng);
    let text = serde_json::to_string_pretty(&json!({
        "systems": systems,
        "linearizations": linearizations,
    }))
    .expect("serialisable");
    std::fs::write(&path, text).expect("the output file can be written");
    println!(
        "wrote {} systems × {STATES} consistent states to {path}",
        systems.len()
    );
}
