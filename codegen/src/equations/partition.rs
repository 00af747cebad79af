//! Stage 3, its last step (after `derive::constraint_equations`, in
//! `analyse_with`): the Gibbs–Appell partition (Udwadia & Kalaba, the
//! explicit Gibbs–Appell equation): the generic rank `r` of `A` and the `r` coordinates whose
//! accelerations are eliminated.
//!
//! Redundancy holds only on the constraint surface, so the rank is
//! measured at *consistent* states: deterministic pseudo-random states
//! projected onto `φ = 0` by Newton's method with minimum-norm steps —
//! positions onto the position-level constraints (Jacobian `∂φ/∂q`, the
//! position-level rows of `A`), then velocities onto every constraint at
//! velocity level (`φ̇` or `φ`, whose Jacobian in `q̇` is `A`). Where no
//! state can be projected the rank off the surface is used instead, and the
//! derivation says so.

use crate::equations::mass_inverse::MassInverse;
use crate::equations::Equations;
use crate::expr::{Id, Sym};
use crate::model::Level;
use crate::numeric::linalg::{independent_columns, minimum_norm_solve};
use crate::numeric::rng::SplitMix64;

/// The partition used by the Gibbs–Appell form.
#[derive(Clone, Debug)]
pub struct Partition {
    /// The generic rank `r` of `A` (on the constraint surface when `on_surface`).
    pub rank: usize,
    /// The `r` eliminated coordinates (`q̈_e`), in the order given or chosen.
    pub eliminated: Vec<usize>,
    /// The generic rank of the position-level rows of `A` alone: how many
    /// coordinates the holonomic constraints determine (the reduced
    /// linearization keeps `n − position_rank` coordinates and `n − rank`
    /// speeds).
    pub position_rank: usize,
    /// Whether `rank` was measured at consistent states.
    pub on_surface: bool,
    /// How many consistent states the rank and the choice were measured at.
    pub states: usize,
}

/// Relative `sin²` below which a column counts as dependent at a consistent
/// state: the projection reaches `|φ| ~ 1e-14`, where a redundant column's
/// `sin²` is ~1e-28; independent columns of generic states are far above.
const RANK_TOLERANCE: f64 = 1e-12;

/// How many consistent states to look for, and how many seeds to try.
const STATES: usize = 8;
const SEEDS: u64 = 64;

/// Finds the rank and the eliminated coordinates; checks `eliminate`.
pub fn partition(eq: &Equations) -> syn::Result<Partition> {
    let n = eq.system.dof();
    let states = consistent_states(eq);
    let on_surface = !states.is_empty();
    if !on_surface {
        contradictions(eq)?;
    }
    let matrices: Vec<Vec<Vec<f64>>> = if on_surface {
        states.iter().map(|s| eval_a(eq, s)).collect()
    } else {
        // No consistent state found: measure off the surface (generic rank).
        random_states(eq, 0x6a1b_b5e1)
            .iter()
            .map(|s| eval_a(eq, s))
            .collect()
    };
    if matches!(eq.mass_inverse, MassInverse::Auxiliary(_)) {
        completes_the_mass(eq, &states)?;
    }
    let rank = matrices
        .iter()
        .map(|a| independent_columns(a, RANK_TOLERANCE).len())
        .max()
        .unwrap_or(0);
    let position_rows: Vec<usize> = (0..eq.a.len())
        .filter(|&i| eq.system.constraints[i].level == Level::Position)
        .collect();
    let position_rank = matrices
        .iter()
        .map(|a| {
            let rows: Vec<Vec<f64>> = position_rows.iter().map(|&i| a[i].clone()).collect();
            independent_columns(&rows, RANK_TOLERANCE).len()
        })
        .max()
        .unwrap_or(0);
    let eliminated = match &eq.system.eliminate {
        Some((given, span)) => {
            if given.len() != rank {
                let names: Vec<String> = eq
                    .system
                    .coordinates
                    .iter()
                    .map(ToString::to_string)
                    .collect();
                return Err(syn::Error::new(
                    *span,
                    format!(
                        "`eliminate` names {} coordinate{} but the rank of A is {rank}{}; \
                         a well-conditioned choice is `eliminate: [{}]`",
                        given.len(),
                        if given.len() == 1 { "" } else { "s" },
                        if on_surface {
                            " on the constraint surface"
                        } else {
                            ""
                        },
                        choose(&matrices, rank, n)
                            .iter()
                            .map(|&i| names[i].as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
            let dependent = matrices.iter().any(|a| {
                let sub: Vec<Vec<f64>> = a
                    .iter()
                    .map(|row| given.iter().map(|&j| row[j]).collect())
                    .collect();
                independent_columns(&sub, RANK_TOLERANCE).len() < rank
            });
            if dependent {
                return Err(syn::Error::new(
                    *span,
                    "the columns of A for these coordinates are dependent at consistent states: \
                     their accelerations cannot be eliminated",
                ));
            }
            given.clone()
        }
        None => choose(&matrices, rank, n),
    };
    Ok(Partition {
        rank,
        eliminated,
        position_rank,
        on_surface,
        states: states.len(),
    })
}

/// `r` columns chosen greedily to be well conditioned at every state: each
/// step takes the column whose smallest residual (over the states) after
/// projecting out the columns already chosen, relative to `‖A‖²_F`, is
/// largest. Relative to `A` rather than to the column itself, so that a
/// column that can vanish (`−sin θ`) loses to one that cannot (`−a`).
///
/// Modified Gram–Schmidt on every state at once: each state keeps the
/// residual of every column and updates it after each choice, so the cost
/// is O(r·n·k) per state.
fn choose(matrices: &[Vec<Vec<f64>>], rank: usize, n: usize) -> Vec<usize> {
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // residuals[s][j]: column j of state s, minus its projection so far.
    let mut residuals: Vec<Vec<Vec<f64>>> = matrices
        .iter()
        .map(|a| {
            (0..n)
                .map(|j| a.iter().map(|row| row[j]).collect())
                .collect()
        })
        .collect();
    let frobenius: Vec<f64> = matrices
        .iter()
        .map(|a| a.iter().flatten().map(|x| x * x).sum())
        .collect();
    let mut chosen: Vec<usize> = Vec::new();
    while chosen.len() < rank {
        let score = |j: usize| -> f64 {
            residuals
                .iter()
                .zip(&frobenius)
                .map(|(r, &f)| if f > 0.0 { dot(&r[j], &r[j]) / f } else { 0.0 })
                .fold(f64::INFINITY, f64::min)
        };
        let best = (0..n)
            .filter(|j| !chosen.contains(j))
            .map(|j| (j, score(j)))
            .fold(None, |best: Option<(usize, f64)>, (j, s)| match best {
                Some((_, b)) if b >= s => best,
                _ => Some((j, s)),
            });
        let Some((p, _)) = best else { break };
        chosen.push(p);
        for columns in residuals.iter_mut() {
            let norm = dot(&columns[p], &columns[p]).sqrt();
            if norm == 0.0 {
                continue;
            }
            let unit: Vec<f64> = columns[p].iter().map(|x| x / norm).collect();
            for (j, column) in columns.iter_mut().enumerate() {
                if !chosen.contains(&j) {
                    let c = dot(column, &unit);
                    column.iter_mut().zip(&unit).for_each(|(x, u)| *x -= c * u);
                }
            }
        }
    }
    chosen
}

/// A state of the system: values of every variable.
#[derive(Clone, Debug)]
pub struct StateValues {
    /// `q`.
    pub q: Vec<f64>,
    /// `q̇`.
    pub qd: Vec<f64>,
    /// `t`.
    pub t: f64,
    /// Parameters.
    pub params: Vec<f64>,
}

impl StateValues {
    fn env(&self) -> impl Fn(Sym) -> f64 + '_ {
        move |s| match s {
            Sym::Coord(i) => self.q[i],
            Sym::Vel(i) => self.qd[i],
            Sym::Time => self.t,
            Sym::Param(i) => self.params[i],
            Sym::Multiplier(_) | Sym::Seed(_) | Sym::Accel(_) => f64::NAN,
        }
    }
}

/// `STATES` random states (off the constraints), from the generator
/// seeded with `stream`: where rank is measured when no consistent state
/// is found.
fn random_states(eq: &Equations, stream: u64) -> Vec<StateValues> {
    let mut rng = SplitMix64::new(stream);
    (0..STATES).map(|_| random_state(eq, &mut rng)).collect()
}

fn random_state(eq: &Equations, rng: &mut SplitMix64) -> StateValues {
    let n = eq.system.dof();
    let mut uniform = |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
    StateValues {
        q: (0..n).map(|_| uniform(-1.0, 1.0)).collect(),
        qd: (0..n).map(|_| uniform(-1.0, 1.0)).collect(),
        t: uniform(0.0, 1.0),
        params: (0..eq.system.parameters.len())
            .map(|_| uniform(0.5, 1.5))
            .collect(),
    }
}

fn eval_a(eq: &Equations, s: &StateValues) -> Vec<Vec<f64>> {
    // All rows in one evaluation: they share their kinematics (the
    // quadruped's feet share the base's), which row by row were walked and
    // evaluated once per row, a quarter of its expansion.
    let entries: Vec<Id> = eq.a.iter().flatten().copied().collect();
    let values = eq.system.graph.eval(&entries, &s.env());
    match eq.a.first().map_or(0, Vec::len) {
        0 => vec![Vec::new(); eq.a.len()],
        n => values.chunks(n).map(<[f64]>::to_vec).collect(),
    }
}

/// A singular `M` is completed by the constraints: `[M; A]` has full column
/// rank at some consistent state (or, without any, at a random one), so
/// that the auxiliary mass `M + s AᵀA` is positive definite there
/// (Udwadia & Schutte 2010). Otherwise no acceleration is determined.
fn completes_the_mass(eq: &Equations, states: &[StateValues]) -> syn::Result<()> {
    let n = eq.system.dof();
    let points: Vec<StateValues> = if states.is_empty() {
        random_states(eq, 0x0a55_1571)
    } else {
        states.to_vec()
    };
    let g = &eq.system.graph;
    let mut best = 0;
    let mut mass_rank = n;
    for s in &points {
        let m: Vec<Vec<f64>> = eq
            .system
            .mass
            .iter()
            .map(|row| g.eval(row, &s.env()))
            .collect();
        mass_rank = mass_rank.min(independent_columns(&m, RANK_TOLERANCE).len());
        let stacked: Vec<Vec<f64>> = m.into_iter().chain(eval_a(eq, s)).collect();
        best = best.max(independent_columns(&stacked, RANK_TOLERANCE).len());
    }
    if best == n {
        return Ok(());
    }
    Err(syn::Error::new(
        eq.system.mass_span,
        format!(
            "the mass matrix is singular (rank {mass_rank} of {n}) and the constraints do not \
             complete it: [M; A] has rank {best} < {n} at every {}state checked, so the \
             accelerations are not determined; add the constraint that fixes the missing \
             direction (e.g. the unit norm of a quaternion)",
            if states.is_empty() { "" } else { "consistent " }
        ),
    ))
}

/// Constraints that no state satisfies, where that can be proved: the rows
/// that are affine in `q` (position level) or in `q̇` (velocity level) with
/// numeric coefficients and offsets, `C x = c`, are consistent exactly when
/// `c` lies in the range of `C`. Called when the search for a consistent
/// state failed; nonlinear or parametric rows are not judged (the search
/// failing proves nothing about them), so this can only reject what is
/// contradictory. The error points at the first row that contradicts the
/// rows before it.
fn contradictions(eq: &Equations) -> syn::Result<()> {
    let g = &eq.system.graph;
    for level in [Level::Position, Level::Velocity] {
        let variable = |s: Sym| match level {
            Level::Position => matches!(s, Sym::Coord(_)),
            Level::Velocity => matches!(s, Sym::Vel(_)),
        };
        let origin = StateValues {
            q: vec![0.0; eq.system.dof()],
            qd: vec![0.0; eq.system.dof()],
            t: 0.0,
            params: vec![0.0; eq.system.parameters.len()],
        };
        // [C | c] of the affine rows so far.
        let mut rows: Vec<Vec<f64>> = Vec::new();
        for (i, c) in eq.system.constraints.iter().enumerate() {
            let affine = c.level == level
                && !g.mentions(c.phi, |s| !variable(s))
                && eq.a[i].iter().all(|&e| g.as_num(e).is_some());
            if !affine {
                continue;
            }
            let offset = g.eval(&[c.phi], &origin.env())[0];
            let mut row: Vec<f64> = eq.a[i]
                .iter()
                .map(|&e| g.eval(&[e], &origin.env())[0])
                .collect();
            row.push(-offset);
            rows.push(row);
            let augmented = independent_columns(&transpose(&rows), RANK_TOLERANCE).len();
            let plain: Vec<Vec<f64>> = rows.iter().map(|r| r[..r.len() - 1].to_vec()).collect();
            if augmented > independent_columns(&transpose(&plain), RANK_TOLERANCE).len() {
                return Err(syn::Error::new_spanned(
                    &c.tokens,
                    "no state satisfies this constraint together with the ones before it: \
                     they are linear with constant coefficients and contradict each other",
                ));
            }
        }
    }
    Ok(())
}

fn transpose(rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let cols = rows.first().map_or(0, Vec::len);
    (0..cols)
        .map(|j| rows.iter().map(|r| r[j]).collect())
        .collect()
}

/// Up to `STATES` consistent states, from deterministic seeds.
pub fn consistent_states(eq: &Equations) -> Vec<StateValues> {
    let mut rng = SplitMix64::new(0x000c_0515_7e47);
    let mut found = Vec::new();
    for _ in 0..SEEDS {
        if found.len() == STATES {
            break;
        }
        let mut s = random_state(eq, &mut rng);
        if project(eq, &mut s) {
            found.push(s);
        }
    }
    found
}

/// Newton with minimum-norm steps; `true` when φ and φ̇ vanish to 1e-13.
fn project(eq: &Equations, s: &mut StateValues) -> bool {
    let g = &eq.system.graph;
    let positions: Vec<usize> = (0..eq.a.len())
        .filter(|&i| eq.system.constraints[i].level == Level::Position)
        .collect();
    let phi: Vec<Id> = positions
        .iter()
        .map(|&i| eq.system.constraints[i].phi)
        .collect();
    let converge = |s: &mut StateValues,
                    residual: &dyn Fn(&StateValues) -> Vec<f64>,
                    rows: &[usize],
                    velocity: bool| {
        for _ in 0..60 {
            let r = residual(s);
            if r.iter().all(|x| x.abs() < 1e-13) {
                return true;
            }
            if r.iter().any(|x| !x.is_finite()) {
                return false;
            }
            let a = eval_a(eq, s);
            let j: Vec<Vec<f64>> = rows.iter().map(|&i| a[i].clone()).collect();
            let step = minimum_norm_solve(&j, &r);
            let target = if velocity { &mut s.qd } else { &mut s.q };
            target.iter_mut().zip(&step).for_each(|(x, d)| *x -= d);
        }
        false
    };
    let all: Vec<usize> = (0..eq.a.len()).collect();
    converge(s, &|s| g.eval(&phi, &s.env()), &positions, false)
        && converge(
            s,
            &|s| g.eval(&eq.velocity_constraints, &s.env()),
            &all,
            true,
        )
}
