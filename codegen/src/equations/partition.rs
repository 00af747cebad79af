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
//!
//! The states must be where the model is used. An orientation lock's rows
//! also vanish at half turns of the lock (`model::rotation`), a surface of
//! its own on which they have rank 1 of 3; from random starts, Newton lands
//! there far more often than on the lock's target (a 2-sphere of half
//! turns against the two quaternions `±1` of a free body's attitude), and
//! where every state did, a free body with one lock measured rank 2 instead
//! of 4 and the model was declared redundant. So positions are first
//! brought onto the locks' branches: damped least-squares steps on the
//! position rows together with the locks' branch residuals `Eᵢᵢ − 1`,
//! which vanish only at the target; the Newton projection then starts
//! there, and a state that leaves a branch is not used.
//!
//! The decision is checked after the fact, at a second batch of consistent
//! states drawn from a generator of its own. The rank is the largest met at
//! any state of either batch: a lower rank is a state that is not generic
//! (a branch point), where the generated code decides at run time
//! (`constrained::rank` verifies every dropped row), whereas a rank set too
//! low would let the run time drop independent rows unchecked. The
//! eliminated coordinates are chosen at the first batch's states of that
//! rank and must stay independent at the check batch's; where they do not,
//! they are chosen again at every state of that rank.

use crate::equations::mass_inverse::MassInverse;
use crate::equations::Equations;
use crate::expr::{Id, Sym};
use crate::model::Level;
use crate::numeric::linalg::{damped_least_squares, independent_columns, minimum_norm_solve};
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
    /// How many consistent states the rank and the choice were measured at
    /// (the first batch).
    pub states: usize,
    /// How many consistent states checked the decision (the second batch).
    pub checked: usize,
    /// How many of the states measured have a rank below `rank` (on the
    /// surface: branch points, where the run time decides).
    pub lower: usize,
}

/// Relative `sin²` below which a column counts as dependent at a consistent
/// state: the projection reaches `|φ| ~ 1e-14`, where a redundant column's
/// `sin²` is ~1e-28; independent columns of generic states are far above.
const RANK_TOLERANCE: f64 = 1e-12;

/// How many consistent states to look for, and how many seeds to try.
const STATES: usize = 8;
const SEEDS: u64 = 64;

/// The seeds of the generators the rank is measured with.
#[derive(Clone, Copy, Debug)]
pub struct Seeds {
    /// The first batch of consistent states.
    pub states: u64,
    /// The batch that checks the decision.
    pub check: u64,
    /// The random states used where no consistent state is found.
    pub random: u64,
}

impl Default for Seeds {
    fn default() -> Self {
        Seeds {
            states: 0x000c_0515_7e47,
            check: 0x0c4e_c4ed_0a11,
            random: 0x6a1b_b5e1,
        }
    }
}

/// Finds the rank and the eliminated coordinates; checks `eliminate`.
pub fn partition(eq: &Equations) -> syn::Result<Partition> {
    partition_with(eq, Seeds::default())
}

/// [`partition`] with the generators' seeds given (tests show that the
/// decision does not depend on them).
pub fn partition_with(eq: &Equations, seeds: Seeds) -> syn::Result<Partition> {
    let n = eq.system.dof();
    let states = consistent_states_from(eq, seeds.states);
    let on_surface = !states.is_empty();
    if !on_surface {
        contradictions(eq)?;
    }
    let first: Vec<Vec<Vec<f64>>> = if on_surface {
        states.iter().map(|s| eval_a(eq, s)).collect()
    } else {
        // No consistent state found: measure off the surface (generic rank).
        random_states(eq, seeds.random)
            .iter()
            .map(|s| eval_a(eq, s))
            .collect()
    };
    let check: Vec<Vec<Vec<f64>>> = if on_surface {
        consistent_states_from(eq, seeds.check)
            .iter()
            .map(|s| eval_a(eq, s))
            .collect()
    } else {
        Vec::new()
    };
    if matches!(eq.mass_inverse, MassInverse::Auxiliary(_)) {
        completes_the_mass(eq, &states)?;
    }
    let rank_of = |a: &Vec<Vec<f64>>| independent_columns(a, RANK_TOLERANCE).len();
    let rank = first.iter().chain(&check).map(rank_of).max().unwrap_or(0);
    let lower = first
        .iter()
        .chain(&check)
        .filter(|a| rank_of(a) < rank)
        .count();
    let (positions, _) = position_rows(eq);
    let position_rank = first
        .iter()
        .chain(&check)
        .map(|a| {
            let rows: Vec<Vec<f64>> = positions.iter().map(|&i| a[i].clone()).collect();
            independent_columns(&rows, RANK_TOLERANCE).len()
        })
        .max()
        .unwrap_or(0);
    // The states of that rank: the generic ones, where the columns are chosen.
    let generic = |batch: &[Vec<Vec<f64>>]| -> Vec<Vec<Vec<f64>>> {
        batch
            .iter()
            .filter(|a| rank_of(a) == rank)
            .cloned()
            .collect()
    };
    let checked = check.len();
    let (first, check) = (generic(&first), generic(&check));
    let eliminated = match &eq.system.eliminate {
        Some((given, span)) => given_columns(eq, given, *span, [&first, &check], rank, on_surface)?,
        None => columns(&first, &check, rank, n),
    };
    Ok(Partition {
        rank,
        eliminated,
        position_rank,
        on_surface,
        states: states.len(),
        checked,
        lower,
    })
}

/// The columns chosen at the first batch, checked at the second: each of
/// its states must keep them independent, or they are chosen again at the
/// states of both.
fn columns(first: &[Vec<Vec<f64>>], check: &[Vec<Vec<f64>>], rank: usize, n: usize) -> Vec<usize> {
    if !first.is_empty() {
        let chosen = choose(first, rank, n);
        if check.iter().all(|a| independent_at(a, &chosen) == rank) {
            return chosen;
        }
    }
    let all: Vec<Vec<Vec<f64>>> = first.iter().chain(check).cloned().collect();
    choose(&all, rank, n)
}

/// The rank of the columns `cols` of `a`.
fn independent_at(a: &[Vec<f64>], cols: &[usize]) -> usize {
    let sub: Vec<Vec<f64>> = a
        .iter()
        .map(|row| cols.iter().map(|&j| row[j]).collect())
        .collect();
    independent_columns(&sub, RANK_TOLERANCE).len()
}

/// The coordinates named in `eliminate`, checked: as many as the rank, and
/// their columns independent at every generic state of both batches.
fn given_columns(
    eq: &Equations,
    given: &[usize],
    span: proc_macro2::Span,
    batches: [&[Vec<Vec<f64>>]; 2],
    rank: usize,
    on_surface: bool,
) -> syn::Result<Vec<usize>> {
    if given.len() != rank {
        let names: Vec<String> = eq
            .system
            .coordinates
            .iter()
            .map(ToString::to_string)
            .collect();
        return Err(syn::Error::new(
            span,
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
                columns(batches[0], batches[1], rank, eq.system.dof())
                    .iter()
                    .map(|&i| names[i].as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let dependent = batches
        .iter()
        .flat_map(|b| b.iter())
        .any(|a| independent_at(a, given) < rank);
    if dependent {
        return Err(syn::Error::new(
            span,
            "the columns of A for these coordinates are dependent at consistent states: \
             their accelerations cannot be eliminated",
        ));
    }
    Ok(given.to_vec())
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
    consistent_states_from(eq, Seeds::default().states)
}

/// Up to `STATES` consistent states, from the generator seeded with `seed`.
pub fn consistent_states_from(eq: &Equations, seed: u64) -> Vec<StateValues> {
    let mut rng = SplitMix64::new(seed);
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

/// The position-level rows: their indices and their `φ`.
fn position_rows(eq: &Equations) -> (Vec<usize>, Vec<Id>) {
    let rows: Vec<usize> = (0..eq.a.len())
        .filter(|&i| eq.system.constraints[i].level == Level::Position)
        .collect();
    let phi = rows.iter().map(|&i| eq.system.constraints[i].phi).collect();
    (rows, phi)
}

/// The orientation locks' branch residuals (`model::Constraint::branch`).
fn branches(eq: &Equations) -> Vec<Id> {
    eq.system
        .constraints
        .iter()
        .filter_map(|c| c.branch)
        .collect()
}

/// Newton with minimum-norm steps, from the locks' branches; `true` when φ
/// and φ̇ vanish to 1e-13 and the state is still on every branch.
fn project(eq: &Equations, s: &mut StateValues) -> bool {
    let g = &eq.system.graph;
    let (positions, phi) = position_rows(eq);
    let branch = branches(eq);
    if !onto_branches(eq, s, &branch) {
        return false;
    }
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
        && g.eval(&branch, &s.env())
            .iter()
            .all(|x| x.abs() < BRANCH_TOLERANCE)
        && converge(
            s,
            &|s| g.eval(&eq.velocity_constraints, &s.env()),
            &all,
            true,
        )
}

/// How near its branch a lock is brought before Newton takes over (and
/// must stay): Newton then moves `q` by about as much, and the half turns
/// are `Eᵢᵢ − 1 ~ −2` away.
const BRANCH_TOLERANCE: f64 = 1e-8;

/// Positions brought onto the locks' branches (module docs): damped
/// least-squares steps on the position rows and the branch residuals
/// together, each step halved until it reduces the residual. The branch
/// residuals' gradients come from central differences (their values need
/// only reach `BRANCH_TOLERANCE`; Newton on the exact rows follows). `true`
/// at once without locks.
fn onto_branches(eq: &Equations, s: &mut StateValues, branch: &[Id]) -> bool {
    if branch.is_empty() {
        return true;
    }
    let g = &eq.system.graph;
    let (positions, phi) = position_rows(eq);
    let residual = |s: &StateValues| -> Vec<f64> {
        let mut r = g.eval(&phi, &s.env());
        r.extend(g.eval(branch, &s.env()));
        r
    };
    let size = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    for _ in 0..100 {
        let r = residual(s);
        if r.iter().any(|x| !x.is_finite()) {
            return false;
        }
        if r.iter().all(|x| x.abs() < BRANCH_TOLERANCE) {
            return true;
        }
        let a = eval_a(eq, s);
        let mut j: Vec<Vec<f64>> = positions.iter().map(|&i| a[i].clone()).collect();
        j.extend(branch_gradients(eq, s, branch));
        let step = damped_least_squares(&j, &r, 1e-12);
        let mut scale = 1.0;
        let accepted = (0..30).any(|_| {
            let mut trial = s.clone();
            trial
                .q
                .iter_mut()
                .zip(&step)
                .for_each(|(x, d)| *x -= scale * d);
            let better = size(&residual(&trial)) < size(&r);
            if better {
                *s = trial;
            }
            scale /= 2.0;
            better
        });
        if !accepted {
            return false;
        }
    }
    false
}

/// `∂(Eᵢᵢ − 1)/∂q` of every branch residual, by central differences.
fn branch_gradients(eq: &Equations, s: &StateValues, branch: &[Id]) -> Vec<Vec<f64>> {
    let g = &eq.system.graph;
    let h = 1e-6;
    let mut rows = vec![vec![0.0; s.q.len()]; branch.len()];
    for j in 0..s.q.len() {
        let mut shifted = s.clone();
        shifted.q[j] = s.q[j] + h;
        let plus = g.eval(branch, &shifted.env());
        shifted.q[j] = s.q[j] - h;
        let minus = g.eval(branch, &shifted.env());
        for (i, row) in rows.iter_mut().enumerate() {
            row[j] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    fn analyse(model: &str) -> Equations {
        crate::analyse(model.parse().expect("tokens"))
            .expect("expands")
            .0
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
        for (model, rank, position_rank, seeds) in cases {
            let eq = analyse(&model);
            let mut rng = SplitMix64::new(0x5eed);
            for _ in 0..seeds {
                let seeds = Seeds {
                    states: rng.next_u64(),
                    check: rng.next_u64(),
                    random: rng.next_u64(),
                };
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
            let seeds = Seeds {
                states: rng.next_u64(),
                check: rng.next_u64(),
                random: rng.next_u64(),
            };
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
}
