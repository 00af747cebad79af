//! Part of stage 3 (`derive`): the exact partial derivatives the Jacobian of `q̈` needs
//! (`docs/math.md`, "Linearization").
//!
//! `q̈(q, q̇, u)` solves `M q̈ = F + Aᵀλ`, `A q̈ = b`. Differentiating both
//! by one variable `v` (a coordinate, a velocity or an input) gives the
//! same constrained system for the tangent `q̈ᵥ = ∂q̈/∂v`:
//!
//! `M q̈ᵥ = F̃ᵥ + Aᵀλᵥ`, `A q̈ᵥ = b̃ᵥ`, with
//! `F̃ᵥ = ∂F/∂v − (∂M/∂v) q̈ + (∂A/∂v)ᵀ λ` and `b̃ᵥ = ∂b/∂v − (∂A/∂v) q̈`,
//!
//! so one factorization serves `q̈` and all its tangents. Here the
//! derivatives of `F`, `M`, `A`, `b` are taken symbolically (exact, and
//! zero where structurally zero); the generated code contracts them with
//! `q̈` and `λ` at run time. For a tree of bodies whose `M` is factored,
//! `∂F/∂v − (∂M/∂v) q̈` is instead `∂(Q − ∂V/∂q)/∂v − ∂τ/∂v` (`τ = M q̈ + c`
//! inverse dynamics, `F = Q − ∂V/∂q − c`), `∂τ` by the recursions of
//! `crate::bodies::derivatives` (as Pinocchio's `computeABADerivatives`
//! does), read with the solved `q̈` bound ([`ThroughInverse`]); for a tree
//! of 16 or more coordinates on an auxiliary mass, `(∂M/∂v) q̈` is
//! `∂(M q̈)/∂v` of the recursions' `M q̈` (O(n) expressions where `M` has
//! n² entries). Two forms:
//!
//! - [`Form::Columns`]: one set of derivatives per column variable. Where
//!   each variable touches a few entries (a chain), this is sparse and the
//!   fastest at run time;
//! - [`Form::Directional`]: one directional derivative `Σᵥ sᵥ ∂/∂v` in the
//!   seeds `Sym::Seed` (forward mode), whose code grows with the DAG of
//!   `F`, `M`, `A`, `b` only; the generated code runs it once per column
//!   with `s` the column's unit vector. Chosen where the columns would
//!   cost more than [`COLUMN_BUDGET`] times as many nodes (a dense `M(q)`
//!   from energies, whose every entry depends on every coordinate: the
//!   16-link pendulum's columns would take 280,000 nodes and 35 MB of code).

use super::point_tangent::PointTangents;
use crate::expr::diff::{Differentiator, Directional};
use crate::expr::{Graph, Id, Sym};

/// The per-column form is kept while its derivatives take at most this many
/// times the nodes of the directional form (plus [`COLUMN_ALLOWANCE`]).
pub const COLUMN_BUDGET: usize = 6;

/// Nodes the per-column form may always take: small systems keep it.
pub const COLUMN_ALLOWANCE: usize = 4_000;

/// The number of coordinates from which the tangents of a tree on an
/// auxiliary mass (not [`ThroughInverse`]) differentiate the recursions'
/// `M q̈` rather than `M`'s entries: on the fixed-base robots, before
/// [`ThroughInverse`], the products won on the 29-joint G1 and lost on
/// the 7-joint Panda and the 12-joint Go1 (in the directional form the
/// seed-free parts of `∂M` leave the loop over the columns, where the
/// products' derivatives stay in it).
pub const PRODUCTS_FROM: usize = 16;

/// The derivatives of `F`, `M`, `A` and `b` by one variable or along one
/// direction.
pub struct Derivatives {
    /// `∂Fᵢ`, per row.
    pub forces: Vec<Id>,
    /// The nonzero `∂Mᵢⱼ` as `(i, j, id)`; empty where `mass_times` is
    /// given instead.
    pub mass: Vec<(usize, usize, Id)>,
    /// `∂(M q̈)ᵢ` per row with `q̈` as `Sym::Accel` (bodies, whose `M q̈`
    /// recursive Newton–Euler writes in O(n)), or through inverse dynamics
    /// `∂τᵢ` (then `forces` holds `∂(Q − ∂V/∂q)ᵢ`); empty where `mass` is
    /// used.
    pub mass_times: Vec<Id>,
    /// The nonzero `∂Aᵣᵢ` as `(r, i, id)`.
    pub a: Vec<(usize, usize, Id)>,
    /// `∂bᵣ`, per row.
    pub b: Vec<Id>,
}

/// How the right-hand sides of the tangent systems are expressed.
pub enum Form {
    /// One [`Derivatives`] per column of the Jacobian.
    Columns(Vec<Derivatives>),
    /// One [`Derivatives`] along the seeds `Sym::Seed(c)`, `c` indexing the
    /// columns.
    Directional(Derivatives),
}

/// The derivatives of `F`, `M`, `A`, `b`, for the columns of the Jacobian:
/// `q₁ … qₙ, q̇₁ … q̇ₙ, u₁ … u_m`.
pub struct Tangent {
    /// The variable of each column.
    pub columns: Vec<Sym>,
    /// Per column, or along a direction.
    pub form: Form,
    /// `∂ψᵣ/∂qⱼ` of the velocity-level constraints `ψ` (`φ̇` or `φ`),
    /// `[r][j]`: how a change of the coordinates moves the velocities the
    /// constraints allow (the reduced linearization).
    pub velocity_constraints: Vec<Vec<Id>>,
}

impl Tangent {
    /// No derivatives: for an expansion without Jacobians.
    pub fn none() -> Tangent {
        Tangent {
            columns: Vec::new(),
            form: Form::Columns(Vec::new()),
            velocity_constraints: Vec::new(),
        }
    }
}

/// Inverse dynamics' derivatives (by the recursions of
/// `crate::bodies::derivatives`), for a tree whose `M` is factored: with
/// `τ = M q̈ + c` and `F = Q − ∂V/∂q − c`, the tangents' `∂F/∂v − (∂M/∂v) q̈`
/// is `∂(Q − ∂V/∂q)/∂v − ∂τ/∂v` at the solved `q̈`, so that neither `M`'s
/// entries nor `c`'s expressions are differentiated.
#[derive(Clone, Copy)]
pub struct ThroughInverse<'a> {
    /// `Q − ∂V/∂q`.
    pub applied: &'a [Id],
    /// `(∂τ/∂q, ∂τ/∂q̇)` with `q̈` as `Sym::Accel`.
    pub jacobian: &'a [Vec<Vec<Id>>; 2],
}

/// What is differentiated: the pieces of the derived equations.
#[derive(Clone, Copy)]
pub struct Pieces<'a> {
    /// `M`.
    pub mass: &'a [Vec<Id>],
    /// `M q̈` with `q̈` as `Sym::Accel`, where the bodies' recursions give it
    /// (and `M` depends on `q`): differentiated instead of `M`'s entries.
    pub mass_times: Option<&'a [Id]>,
    /// Inverse dynamics' derivatives, which replace those of `M` and `F`
    /// where the per-column form serves.
    pub through_inverse: Option<ThroughInverse<'a>>,
    /// `F`.
    pub forces: &'a [Id],
    /// `A`.
    pub a: &'a [Vec<Id>],
    /// `b`.
    pub b: &'a [Id],
    /// `ψ`, the constraints at velocity level.
    pub velocity_constraints: &'a [Id],
    /// The rows of points under a free base, whose terms come from the
    /// points' motion ([`super::point_tangent`]) where their paths allow.
    pub in_base: &'a [super::in_base::InBaseRows],
}

/// The pieces' derivatives, each entry by `derivative`.
fn derivatives(
    g: &mut Graph,
    p: &Pieces,
    mut derivative: impl FnMut(&mut Graph, Id) -> Id,
) -> Derivatives {
    let forces = p.forces.iter().map(|&f| derivative(g, f)).collect();
    let mut mass = Vec::new();
    let mass_times = match p.mass_times {
        Some(products) => products.iter().map(|&e| derivative(g, e)).collect(),
        None => Vec::new(),
    };
    let entries = if p.mass_times.is_some() {
        &[][..]
    } else {
        p.mass
    };
    for (i, row) in entries.iter().enumerate() {
        for (j, &m) in row.iter().enumerate() {
            let dm = derivative(g, m);
            if !g.is_zero(dm) {
                mass.push((i, j, dm));
            }
        }
    }
    let mut a = Vec::new();
    for (r, row) in p.a.iter().enumerate() {
        for (i, &e) in row.iter().enumerate() {
            let da = derivative(g, e);
            if !g.is_zero(da) {
                a.push((r, i, da));
            }
        }
    }
    let b = p.b.iter().map(|&e| derivative(g, e)).collect();
    Derivatives {
        forces,
        mass,
        mass_times,
        a,
        b,
    }
}

/// Differentiates `F`, `M`, `A`, `b` by every column variable (`q₁ … qₙ`,
/// `q̇₁ … q̇ₙ`, then `inputs`), per column or along a direction (see the
/// module docs), and `ψ` by the coordinates.
pub fn tangent(g: &mut Graph, p: &Pieces, inputs: &[Sym]) -> Tangent {
    let n = p.forces.len();
    let columns: Vec<Sym> = (0..n)
        .map(Sym::Coord)
        .chain((0..n).map(Sym::Vel))
        .chain(inputs.iter().copied())
        .collect();
    let points = super::point_tangent::point_tangents(g, p.in_base, n);
    let form = match p.through_inverse {
        Some(r) => through_inverse_form(g, p, r, (&columns, &points)),
        None => None,
    };
    let form = form.unwrap_or_else(|| form_of(g, p, &columns, true));
    let mut d = Differentiator::new();
    let zero = g.int(0);
    let velocity_constraints = (p.velocity_constraints.iter().enumerate())
        .map(|(r, &psi)| {
            if points.rows.contains(&r) {
                // A point's rows: from its motion, every other entry zero.
                let mut row = vec![zero; n];
                for &(_, j, e) in points.velocity.iter().filter(|v| v.0 == r) {
                    row[j] = e;
                }
                return row;
            }
            let nodes = g.reachable(&[psi]);
            (0..n)
                .map(|j| {
                    for &id in &nodes {
                        d.partial(g, id, Sym::Coord(j));
                    }
                    d.partial(g, psi, Sym::Coord(j))
                })
                .collect()
        })
        .collect();
    Tangent {
        columns,
        form,
        velocity_constraints,
    }
}

/// The per-column form through inverse dynamics' derivatives:
/// `Q − ∂V/∂q`, `A` and `b` differentiated per column, `∂τ`'s
/// column as `mass_times`; `None` where those columns would exceed the
/// budget (then [`form_of`] decides on `F` and `M`).
fn through_inverse_form(
    g: &mut Graph,
    p: &Pieces,
    r: ThroughInverse,
    (columns, points): (&[Sym], &PointTangents),
) -> Option<Form> {
    let n = p.forces.len();
    // The points' rows are left out of `A` and `b` here: their terms
    // come whole from `points`.
    let zero = g.int(0);
    let mut a = p.a.to_vec();
    let mut b = p.b.to_vec();
    for &row in &points.rows {
        a[row].iter_mut().for_each(|e| *e = zero);
        b[row] = zero;
    }
    let plain = Pieces {
        mass: &[],
        mass_times: None,
        through_inverse: None,
        forces: r.applied,
        a: &a,
        b: &b,
        ..*p
    };
    let Form::Columns(mut per_column) = form_of(g, &plain, columns, false) else {
        return None;
    };
    for (c, d) in per_column.iter_mut().enumerate().take(2 * n) {
        let by = &r.jacobian[c / n];
        d.mass_times = (0..n).map(|i| by[i][c % n]).collect();
        for &(i, e) in &points.forces[c] {
            d.forces[i] = g.add2(d.forces[i], e);
        }
        for &(row, e) in &points.rhs[c] {
            d.b[row] = g.add2(d.b[row], e);
        }
    }
    Some(Form::Columns(per_column))
}

/// The derivatives per column where they stay within [`COLUMN_BUDGET`] of
/// the directional form's nodes (plus [`COLUMN_ALLOWANCE`]), else along
/// the seeds. Where `extrapolate`, the attempt stops as soon as the
/// columns so far, extrapolated to all, exceed the budget (a dense `M(q)`'s
/// first columns are not cheaper than its last); else only once they do
/// (a free base's columns come first and are the densest: the Go1's
/// first five, extrapolated, made 25,600 nodes of `A` and `b` where all
/// fifty take 8,451).
fn form_of(g: &mut Graph, p: &Pieces, columns: &[Sym], extrapolate: bool) -> Form {
    // Differentiate every node below the roots in arena order first, so
    // that the memoised recursions are one level deep however deep the
    // expressions are.
    let mut roots: Vec<Id> = p.forces.to_vec();
    match p.mass_times {
        Some(products) => roots.extend(products),
        None => roots.extend(p.mass.iter().flatten()),
    }
    roots.extend(p.a.iter().flatten());
    roots.extend(p.b);
    let order = g.reachable(&roots);
    let before = g.len();
    let mut directional = Directional::new(columns);
    for &id in &order {
        directional.derivative(g, id);
    }
    let along = derivatives(g, p, |g, e| directional.derivative(g, e));
    let budget = COLUMN_BUDGET * (g.len() - before) + COLUMN_ALLOWANCE;
    let mut d = Differentiator::new();
    let start = g.len();
    let mut per_column = Vec::with_capacity(columns.len());
    for (c, &v) in columns.iter().enumerate() {
        for &id in &order {
            d.partial(g, id, v);
        }
        // Stop as soon as the columns so far, extrapolated to all of
        // them where `extrapolate`, exceed the budget: the attempt itself
        // must stay cheap.
        let so_far = g.len() - start;
        let over = if extrapolate {
            so_far * columns.len() > budget * (c + 1)
        } else {
            so_far > budget
        };
        if over {
            break;
        }
        per_column.push(derivatives(g, p, |g, e| d.partial(g, e, v)));
    }
    if per_column.len() == columns.len() {
        Form::Columns(per_column)
    } else {
        Form::Directional(along)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tools::fixtures::{joint_angle_pendulum, planar_chain};

    fn form(source: &str) -> (bool, usize) {
        let eq = crate::analyse(source.parse().expect("tokens")).expect("expands");
        let directional = matches!(eq.tangent.form, Form::Directional(_));
        (directional, eq.system.graph.len())
    }

    /// Chains keep one sparse set of derivatives per column; a dense `M(q)`
    /// from energies switches to the directional form before its columns
    /// blow up (the 16-link pendulum's took 280,000 nodes; the directional
    /// form keeps the whole graph under 100,000).
    #[test]
    fn columns_where_sparse_directional_where_dense() {
        assert!(!form(&planar_chain("Chain", 32)).0);
        assert!(!form(&joint_angle_pendulum("Pendulum", 4)).0);
        let (directional, nodes) = form(&joint_angle_pendulum("Pendulum", 16));
        assert!(directional);
        assert!(nodes < 100_000, "{nodes} nodes");
    }

    /// The directional derivative along the unit seed of a column is that
    /// column's partial derivative, at random points.
    #[test]
    fn directional_derivative_is_the_partial_along_a_unit_seed() {
        let mut eq =
            crate::analyse(joint_angle_pendulum("P", 3).parse().expect("tokens")).expect("ok");
        let g = &mut eq.system.graph;
        let f = eq.system.forces.clone();
        let columns: Vec<Sym> = (0..3).map(Sym::Coord).chain((0..3).map(Sym::Vel)).collect();
        let mut directional = Directional::new(&columns);
        let mut d = Differentiator::new();
        for (c, &v) in columns.iter().enumerate() {
            for &fi in &f {
                let along = directional.derivative(g, fi);
                let partial = d.partial(g, fi, v);
                for point in crate::numeric::rng::sample_points(0) {
                    let value = |s: Sym| match s {
                        Sym::Seed(k) => f64::from(u8::from(k == c)),
                        s => point(s),
                    };
                    let both = g.eval(&[along, partial], &value);
                    assert!(
                        (both[0] - both[1]).abs() <= 1e-12 * (1.0 + both[1].abs()),
                        "column {c}: {} vs {}",
                        both[0],
                        both[1]
                    );
                }
            }
        }
    }
}
