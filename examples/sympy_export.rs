//! Writes every reference model as JSON for the independent sympy suite
//! (`tests/sympy/`): the macro's `SYMBOLIC` expressions and constraint
//! levels, and numbers at consistent states — random states projected onto
//! the constraints by the runtime — for `A`, `b`, `q̈` of both equations of
//! motion and the constraint force.
//!
//! `cargo run --example sympy_export -- target/sympy/systems.json`

use constrained::models::*;
use constrained::nalgebra::SVector;
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
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/sympy/systems.json".to_string());
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
            |p| ChaplyginSleigh::new(p[0], p[1], p[2]),
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
    let text = serde_json::to_string_pretty(&json!({ "systems": systems })).expect("serialisable");
    std::fs::write(&path, text).expect("the output file can be written");
    println!(
        "wrote {} systems × {STATES} consistent states to {path}",
        systems.len()
    );
}
