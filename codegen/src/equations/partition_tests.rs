//! The partition's unit tests: lock branches, seeds and the checked
//! decision.

use super::*;
use crate::equations::surface::{branches, eval_a, STATES};
use crate::numeric::rng::SplitMix64;

fn analyse(model: &str) -> Equations {
    crate::analyse(model.parse().expect("tokens")).expect("expands")
}

/// Seeds for both batches and the random states, drawn from `rng`.
fn seeds(rng: &mut SplitMix64) -> Seeds {
    Seeds {
        states: rng.next_u64(),
        check: rng.next_u64(),
        random: rng.next_u64(),
    }
}

/// A free brick with its attitude locked (to `attitude`) and `unused`
/// parameters, which moved the states' draws: with 5, 7, 8 or 10 every
/// state the Newton projection found was a half turn of the lock.
fn locked_brick(unused: usize, attitude: &str) -> String {
    let params: Vec<String> = (0..unused).map(|i| format!("p{i}")).collect();
    format!(
        "pub struct Brick {{
            parameters: [{}],
            bodies: [
                brick {{
                    joint: free(x, y, z, qw, qx, qy, qz),
                    mass: 2.0,
                    com: [0.1, 0.05, -0.2],
                    inertia: diag[0.01, 0.02, 0.03],
                }},
            ],
            constraints: [orientation(brick) == {attitude}],
        }}",
        params.join(", ")
    )
}

/// A biped standing on flat feet: a floating pelvis, two legs of six
/// revolute joints, each foot held in place and in attitude (6 rows a
/// foot, 13 with the quaternion's norm, all independent).
fn biped() -> String {
    let leg = |side: &str, y: f64| {
        let joints = [
            ("hip_yaw", "[0.0, 0.0, 1.0]", format!("[0.0, {y}, -0.1]")),
            (
                "hip_roll",
                "[1.0, 0.0, 0.0]",
                "[0.0, 0.0, -0.05]".to_string(),
            ),
            (
                "hip_pitch",
                "[0.0, 1.0, 0.0]",
                "[0.0, 0.0, -0.05]".to_string(),
            ),
            ("knee", "[0.0, 1.0, 0.0]", "[0.0, 0.0, -0.3]".to_string()),
            (
                "ankle_pitch",
                "[0.0, 1.0, 0.0]",
                "[0.0, 0.0, -0.3]".to_string(),
            ),
            (
                "ankle_roll",
                "[1.0, 0.0, 0.0]",
                "[0.0, 0.0, -0.02]".to_string(),
            ),
        ];
        let mut parent = "pelvis".to_string();
        let mut out = String::new();
        for (joint, axis, xyz) in joints {
            let name = format!("{joint}_{side}");
            out += &format!(
                "{name} {{ parent: {parent}, joint: revolute(q_{name}, {axis}), xyz: {xyz},
                    mass: 1.0, inertia: diag[0.01, 0.01, 0.01] }},"
            );
            parent = name;
        }
        out
    };
    format!(
        "pub struct Biped {{
            parameters: [lx, ly, rx, ry],
            bodies: [
                pelvis {{
                    joint: free(x, y, z, qw, qx, qy, qz),
                    mass: 5.0,
                    inertia: diag[0.05, 0.04, 0.03],
                }},
                {} {}
            ],
            constraints: [
                position(ankle_roll_l, [0.0, 0.0, -0.04]) == [lx, ly, 0.0],
                orientation(ankle_roll_l) == [0.0, 0.0, 0.0],
                position(ankle_roll_r, [0.0, 0.0, -0.04]) == [rx, ry, 0.0],
                orientation(ankle_roll_r) == [0.0, 0.0, 0.0],
            ],
        }}",
        leg("l", 0.1),
        leg("r", -0.1)
    )
}

/// A half turn of a lock is a consistent state (its rows vanish) where
/// the rows lose rank: what the projection must not measure at.
#[test]
fn a_half_turn_satisfies_the_lock_and_loses_rank() {
    let eq = analyse(&locked_brick(0, "[0.0, 0.0, 0.0]"));
    let (_, phi) = position_rows(&eq);
    let g = &eq.system.graph;
    let at = |quaternion: [f64; 4]| StateValues {
        q: [0.3, -0.2, 0.5].into_iter().chain(quaternion).collect(),
        qd: vec![0.0; 7],
        t: 0.0,
        params: Vec::new(),
    };
    let s = 0.5f64.sqrt();
    let half_turn = at([0.0, s, 0.0, s]);
    assert!(g
        .eval(&phi, &half_turn.env())
        .iter()
        .all(|x| x.abs() < 1e-15));
    assert_eq!(
        independent_columns(&eval_a(&eq, &half_turn), RANK_TOLERANCE).len(),
        2
    );
    assert!(g
        .eval(&branches(&eq), &half_turn.env())
        .iter()
        .any(|x| x.abs() > 1.0));
    let target = at([1.0, 0.0, 0.0, 0.0]);
    assert_eq!(
        independent_columns(&eval_a(&eq, &target), RANK_TOLERANCE).len(),
        4
    );
}

/// The free brick with one lock: no redundancy, whatever the number of
/// parameters (they share the states' generator) and the lock's target,
/// and every consistent state on the lock's branch.
#[test]
fn a_locked_free_brick_has_no_redundancy_for_any_parameter_list() {
    for attitude in ["[0.0, 0.0, 0.0]", "[0.3, -1.2, 2.9]", "[p0, p1, p2]"] {
        for unused in 3..=10 {
            let eq = analyse(&locked_brick(unused, attitude));
            let p = partition(&eq).expect("partition");
            let case = format!("{attitude} with {unused} parameters");
            assert_eq!((p.rank, p.position_rank), (4, 4), "{case}");
            assert_eq!(
                (p.states, p.checked, p.lower),
                (STATES, STATES, 0),
                "{case}"
            );
            assert!(
                p.eliminated.iter().all(|&c| c >= 3),
                "{case}: {:?}",
                p.eliminated
            );
        }
    }
    for unused in 0..3 {
        let eq = analyse(&locked_brick(unused, "[0.0, 0.0, 0.0]"));
        assert_eq!(
            partition(&eq).expect("partition").rank,
            4,
            "{unused} parameters"
        );
    }
}

/// The rank decision is the same for every seed of both batches: the
/// locked brick, the biped on flat feet (13 independent rows), and a
/// model redundant on its surface (the parallelogram four-bar with its
/// tips' distance, rank 8 of 9, which stays redundant).
#[test]
fn the_decision_does_not_depend_on_the_seeds() {
    let four_bar = "pub struct FourBarWithTipDistance {
        coordinates: [x1, y1, p1, x2, y2, p2, x3, y3, p3],
        parameters: [m, jm, l, d, g],
        mass: diag[m, m, jm, m, m, jm, m, m, jm],
        forces: [0.0, -m * g, 0.0, 0.0, -m * g, 0.0, 0.0, -m * g, 0.0],
        constraints: [
            x1 - l / 2.0 * p1.cos() == 0.0,
            y1 - l / 2.0 * p1.sin() == 0.0,
            x1 + l / 2.0 * p1.cos() == x2 - d / 2.0 * p2.cos(),
            y1 + l / 2.0 * p1.sin() == y2 - d / 2.0 * p2.sin(),
            x3 - l / 2.0 * p3.cos() == d,
            y3 - l / 2.0 * p3.sin() == 0.0,
            x3 + l / 2.0 * p3.cos() == x2 + d / 2.0 * p2.cos(),
            y3 + l / 2.0 * p3.sin() == y2 + d / 2.0 * p2.sin(),
            (x3 + l / 2.0 * p3.cos() - x1 - l / 2.0 * p1.cos()).powi(2)
                + (y3 + l / 2.0 * p3.sin() - y1 - l / 2.0 * p1.sin()).powi(2) == d.powi(2),
        ],
    }";
    let cases = [
        (locked_brick(5, "[0.0, 0.0, 0.0]"), 4, 4, 24),
        (biped(), 13, 13, 6),
        (four_bar.to_string(), 8, 8, 12),
    ];
    for (model, rank, position_rank, draws) in cases {
        let eq = analyse(&model);
        let mut rng = SplitMix64::new(0x5eed);
        for _ in 0..draws {
            let seeds = seeds(&mut rng);
            let p = partition_with(&eq, seeds).expect("partition");
            let name = &eq.system.name;
            assert_eq!(
                (p.rank, p.position_rank),
                (rank, position_rank),
                "{name}: {seeds:?}"
            );
            assert!(p.states > 0 && p.checked > 0, "{name}: {seeds:?}");
            // The columns chosen are independent at every state of rank r.
            for s in consistent_states_from(&eq, seeds.check) {
                let a = eval_a(&eq, &s);
                if independent_columns(&a, RANK_TOLERANCE).len() == rank {
                    assert_eq!(independent_at(&a, &p.eliminated), rank, "{name}: {seeds:?}");
                }
            }
        }
    }
}

/// Two components of the surface, `x = 0` (rank 1) and `y = z = 1`
/// (rank 2): both are met, the rank is the larger whatever the seeds,
/// and the states of the smaller are counted (the run time decides
/// there). Only states exactly on `x = 0` count: one that Newton left
/// at `x ~ 1e-13` has rank 2 to the column-relative tolerance.
#[test]
fn states_of_lower_rank_leave_the_rank_to_the_largest() {
    let eq = analyse(
        "pub struct TwoComponents {
            coordinates: [x, y, z],
            mass: diag[1.0, 1.0, 1.0],
            forces: [0.0, 0.0, 0.0],
            constraints: [x * (y - 1.0) == 0.0, x * (z - 1.0) == 0.0],
        }",
    );
    let p = partition(&eq).expect("partition");
    assert!(p.lower > 0 && p.lower < p.states + p.checked, "{p:?}");
    let mut rng = SplitMix64::new(0x10e5);
    for _ in 0..50 {
        let seeds = seeds(&mut rng);
        let p = partition_with(&eq, seeds).expect("partition");
        assert_eq!((p.rank, p.position_rank), (2, 2), "{seeds:?}");
    }
}

/// Columns chosen at the first batch that a state of the check batch
/// makes dependent are chosen again at both.
#[test]
fn columns_dependent_at_the_check_are_chosen_again() {
    let first = vec![vec![vec![1.0, 0.5, 0.1]]];
    assert_eq!(columns(&first, &[], 1, 3), vec![0]);
    let check = vec![vec![vec![0.0, 1.0, 0.2]]];
    assert_eq!(columns(&first, &check, 1, 3), vec![1]);
    // A check that keeps them independent keeps the first choice.
    let check = vec![vec![vec![0.3, 1.0, 0.2]]];
    assert_eq!(columns(&first, &check, 1, 3), vec![0]);
}

/// A free brick held at three points whose targets are parameters: the
/// nine rows have rank 6 (7 with the quaternion's norm), and they are
/// consistent only where the targets keep the brick's distances, which
/// random parameters never do. The projection moves the targets with
/// `q`, so the rank is measured on the surface, whatever the seeds, at
/// states where every row holds.
#[test]
fn points_held_at_parameters_are_measured_on_the_surface() {
    let eq = analyse(
        "pub struct HeldBrick {
            parameters: [a1, a2, a3, b1, b2, b3, c1, c2, c3],
            bodies: [
                brick {
                    joint: free(x, y, z, qw, qx, qy, qz),
                    mass: 2.0,
                    inertia: diag[0.01, 0.02, 0.03],
                },
            ],
            constraints: [
                position(brick, [0.1, 0.0, 0.0]) == [a1, a2, a3],
                position(brick, [0.0, 0.2, 0.0]) == [b1, b2, b3],
                position(brick, [0.0, 0.0, 0.3]) == [c1, c2, c3],
            ],
        }",
    );
    let (_, phi) = position_rows(&eq);
    let g = &eq.system.graph;
    let mut rng = SplitMix64::new(0x0b51);
    for _ in 0..8 {
        let seeds = seeds(&mut rng);
        let p = partition_with(&eq, seeds).expect("partition");
        assert!(p.on_surface, "{seeds:?}");
        assert_eq!((p.rank, p.position_rank), (7, 7), "{seeds:?}");
        assert_eq!((p.states, p.checked), (STATES, STATES), "{seeds:?}");
        for s in consistent_states_from(&eq, seeds.check) {
            assert!(
                g.eval(&phi, &s.env()).iter().all(|x| x.abs() < 1e-13),
                "{seeds:?}"
            );
            // The targets moved to where a rigid brick reaches them.
            let target = |k: usize| [s.params[3 * k], s.params[3 * k + 1], s.params[3 * k + 2]];
            let distance = |u: [f64; 3], v: [f64; 3]| {
                u.iter()
                    .zip(v)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            let expected = [0.05f64.sqrt(), 0.13f64.sqrt(), 0.10f64.sqrt()];
            let found = [
                distance(target(0), target(1)),
                distance(target(1), target(2)),
                distance(target(0), target(2)),
            ];
            for (e, f) in expected.iter().zip(found) {
                assert!((e - f).abs() < 1e-12, "{seeds:?}: {found:?}");
            }
        }
    }
}
