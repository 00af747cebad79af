//! Stage 3, its last step (after `constraint_equations`, in
//! `super::derive`): the Gibbs–Appell partition (Udwadia & Kalaba, the
//! explicit Gibbs–Appell equation): the generic rank `r` of `A` and the `r` coordinates whose
//! accelerations are eliminated.
//!
//! Redundancy holds only on the constraint surface, so the rank is
//! measured at *consistent* states: deterministic pseudo-random states
//! projected onto `φ = 0` by Newton's method with minimum-norm steps —
//! positions onto the position-level constraints (Jacobian `∂φ/∂q`, the
//! position-level rows of `A`), then velocities onto every constraint at
//! velocity level (`φ̇` or `φ`, whose Jacobian in `q̇` is `A`). Where no
//! state is reached by moving `q` alone and the position rows read
//! parameters, the parameters move too (points held at parameters are
//! consistent only for some of their values). Where no state can be
//! projected the rank off the surface is used instead, and the derivation
//! says so.
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

pub use super::surface::{consistent_states, consistent_states_from, Seeds, StateValues};
use super::surface::{position_rows, random_states, Surface};
use crate::equations::mass_inverse::MassInverse;
use crate::equations::Equations;
use crate::expr::{Id, Sym};
use crate::model::Level;
use crate::numeric::linalg::independent_columns;

/// The partition used by the Gibbs–Appell form.
#[derive(Clone, Debug, Default)]
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

/// Finds the rank and the eliminated coordinates; checks `eliminate`.
pub fn partition(eq: &Equations) -> syn::Result<Partition> {
    partition_with(eq, Seeds::default())
}

/// [`partition`] with the generators' seeds given (tests show that the
/// decision does not depend on them).
pub fn partition_with(eq: &Equations, seeds: Seeds) -> syn::Result<Partition> {
    let n = eq.system.dof();
    let surface = Surface::new(eq);
    let states = surface.consistent_states_from(seeds.states);
    let on_surface = !states.is_empty();
    if !on_surface {
        contradictions(eq)?;
    }
    let first: Vec<Vec<Vec<f64>>> = if on_surface {
        states.iter().map(|s| surface.a(s)).collect()
    } else {
        // No consistent state found: measure off the surface (generic rank).
        random_states(eq, seeds.random)
            .iter()
            .map(|s| surface.a(s))
            .collect()
    };
    let check: Vec<Vec<Vec<f64>>> = if on_surface {
        surface
            .consistent_states_from(seeds.check)
            .iter()
            .map(|s| surface.a(s))
            .collect()
    } else {
        Vec::new()
    };
    if matches!(eq.mass_inverse, MassInverse::Auxiliary(_)) {
        completes_the_mass(eq, &surface, &states)?;
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

/// A singular `M` is completed by the constraints: `[M; A]` has full column
/// rank at some consistent state (or, without any, at a random one), so
/// that the auxiliary mass `M + s AᵀA` is positive definite there
/// (Udwadia & Schutte 2010). Otherwise no acceleration is determined.
fn completes_the_mass(
    eq: &Equations,
    surface: &Surface,
    states: &[StateValues],
) -> syn::Result<()> {
    let n = eq.system.dof();
    let points: Vec<StateValues> = if states.is_empty() {
        random_states(eq, 0x0a55_1571)
    } else {
        states.to_vec()
    };
    let entries: Vec<Id> = eq.system.mass.iter().flatten().copied().collect();
    let mass = eq.system.graph.tape(&entries);
    let mut best = 0;
    let mut mass_rank = n;
    for s in &points {
        let values = mass.eval(&s.env());
        let mut rest = values.as_slice();
        let m: Vec<Vec<f64>> = eq
            .system
            .mass
            .iter()
            .map(|row| {
                let (this, next) = rest.split_at(row.len());
                rest = next;
                this.to_vec()
            })
            .collect();
        mass_rank = mass_rank.min(independent_columns(&m, RANK_TOLERANCE).len());
        let stacked: Vec<Vec<f64>> = m.into_iter().chain(surface.a(s)).collect();
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

#[cfg(test)]
#[path = "partition_tests.rs"]
mod tests;
