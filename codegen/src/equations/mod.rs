//! Stage 3: [`System`] → [`Equations`]: the constraints differentiated into
//! `A q̈ = b` by the total-derivative rule; then Gauss's principle
//! ([`mass_inverse`]) and the tangent pieces (`tangent`).

pub mod gibbs_appell;
pub mod in_base;
pub mod mass_inverse;
pub mod partition;
pub mod saddle_point;
mod surface;
pub(crate) mod tangent;
pub mod velocity;

use crate::expr::common_factors::Factorer;
use crate::expr::diff::{AtRest, Differentiator};
use crate::expr::Id;
use crate::expr::Sym;
use crate::model::{Level, System};
use mass_inverse::MassInverse;
use tangent::{Pieces, Tangent};

/// A system together with its derived constraint equations.
pub struct Equations {
    /// The checked input.
    pub system: System,
    /// `A`, k × n: `Aᵢⱼ = ∂ψᵢ/∂q̈ⱼ`.
    pub a: Vec<Vec<Id>>,
    /// `b`, k: `bᵢ = −ψᵢ|_{q̈=0}`.
    pub b: Vec<Id>,
    /// The constraints at velocity level: `φ̇` for position-level `φ`, `φ`
    /// itself otherwise. Zero on consistent states; its Jacobian in `q̇` is `A`.
    pub velocity_constraints: Vec<Id>,
    /// How Gauss's principle is solved (see [`mass_inverse`]).
    pub mass_inverse: MassInverse,
    /// The derivatives of `F`, `M`, `A`, `b` behind `acceleration_jacobian`
    /// (see `equations::tangent`); none when not `jacobians`.
    pub tangent: Tangent,
    /// Whether the Jacobian and linearization are generated
    /// ([`crate::Options`]).
    pub jacobians: bool,
    /// The generalized momentum `p = M(q, t) q̇`, n entries.
    pub momentum: Vec<Id>,
}

/// Differentiates every constraint: velocity-level φ once, position-level φ
/// twice (`ψ = D φ` or `ψ = D(D φ)`), and splits `ψ` into `A q̈ − b`.
///
/// Rows are not normalised: `A` and `b` are the derivatives of φ exactly as
/// written, so that a user's scaling of φ shows up unchanged.
/// `M`, `F`, `A` and `b` have their common factors pulled out
/// ([`crate::expr::common_factors`]) before anything is built from them, so that the
/// derivation and the code both carry the factored forms.
pub fn constraint_equations(mut system: System, jacobians: bool) -> Equations {
    let n = system.dof();
    let mut d = Differentiator::new();
    let mut factorer = Factorer::keeping(system.named.iter().map(|(_, id)| *id));
    let g = &mut system.graph;
    if let Some(b) = system.bodies.as_mut() {
        b.velocity_forces = velocity::forces(g, b, &system.forces);
    }
    system.mass = factorer.factor_rows(g, &system.mass);
    system.forces = factorer.factor_all(g, &system.forces);
    if let Some(b) = system.bodies.as_mut() {
        velocity::factor(g, &mut factorer, b);
    }
    let in_base = in_base::rows(g, &system.constraints, n);
    let (mut a, mut b, mut velocity_constraints) = (Vec::new(), Vec::new(), Vec::new());
    let mut at_rest = AtRest::default();
    let mut structured = Vec::new();
    for c in &system.constraints {
        let velocity_level = match c.level {
            Level::Velocity => c.phi,
            // φ has no q̇, so D φ = Σ ∂φ/∂qⱼ q̇ⱼ + ∂φ/∂t has no q̈ term.
            Level::Position => d.time_derivative(g, c.phi, n).1,
        };
        let (row, rest) = d.time_derivative(g, velocity_level, n);
        a.push(factorer.factor_all(g, &row));
        let rhs = g.neg(rest);
        b.push(rhs);
        velocity_constraints.push(velocity_level);
        // The same `b` by forward mode over φ's own structure.
        let velocity = match c.level {
            Level::Velocity => c.phi,
            Level::Position => at_rest.derivative(g, c.phi),
        };
        let rest = at_rest.derivative(g, velocity);
        structured.push(g.neg(rest));
    }
    let b = cheaper_bias(
        g,
        &mut factorer,
        (&system.mass, &system.forces, &a),
        &b,
        &structured,
    );
    // b = −(d/dt A)·q̇ is a quadratic form in q̇: written as a sum of
    // squares where that shortens the code, counted with everything else
    // that is computed beside it (crate::expr::squares).
    let mut b = complete_squares(g, &mut factorer, &system.mass, &system.forces, &a, &b);
    // The rows of points under a free base in their closed form
    // (`in_base`): the same values, without the quotient rule of `R̂`.
    for rows in &in_base {
        for (i, &r) in rows.rows.iter().enumerate() {
            a[r] = factorer.factor_all(g, &rows.model_a[i]);
            b[r] = factorer.factor(g, rows.model_b[i]);
        }
    }
    let g = &mut system.graph;
    let tree = system.bodies.as_ref().and_then(|t| {
        Some(mass_inverse::Bodies {
            mass: t.velocity_mass.as_deref()?,
            forces: t.velocity_forces.as_deref()?,
            bodies: &t.tree[..],
            in_base: &in_base[..],
        })
    });
    let mass_inverse = mass_inverse::build(
        g,
        &mut factorer,
        (&system.mass, tree),
        &system.forces,
        &a,
        &b,
    );
    let inputs: Vec<Sym> = (0..system.inputs).map(|j| system.input(j)).collect();
    let pieces = Pieces {
        mass: &system.mass,
        forces: &system.forces,
        a: &a,
        b: &b,
        velocity_constraints: &velocity_constraints,
    };
    let tangent = if jacobians {
        tangent::tangent(&mut system.graph, &pieces, &inputs)
    } else {
        Tangent::none()
    };
    let momentum = momentum(&mut system.graph, &system.mass);
    Equations {
        momentum,
        jacobians,
        system,
        a,
        b,
        velocity_constraints,
        mass_inverse,
        tangent,
    }
}

/// `M q̇`, row by row; structural zeros of `M` vanish.
fn momentum(g: &mut crate::expr::Graph, mass: &[Vec<Id>]) -> Vec<Id> {
    mass.iter()
        .map(|row| {
            let terms: Vec<Id> = row
                .iter()
                .enumerate()
                .map(|(j, &m)| {
                    let v = g.sym(Sym::Vel(j));
                    g.mul2(m, v)
                })
                .collect();
            g.add(&terms)
        })
        .collect()
}

/// The entries of `M`, `A` and `F`: what the code computes beside `b`.
fn pieces(mass: &[Vec<Id>], forces: &[Id], a: &[Vec<Id>]) -> Vec<Id> {
    mass.iter()
        .chain(a)
        .flatten()
        .chain(forces)
        .copied()
        .collect()
}

/// Per row, `b` from the partials (`Σᵢⱼ ∂²φ/∂qᵢ∂qⱼ·q̇ᵢq̇ⱼ`) or from
/// forward mode (`D₀ D₀ φ`, [`AtRest`]), whichever costs fewer operations
/// once factored, counted with `M`, `F`, `A` and the rows before (whose
/// subexpressions it may share): equal values, so the choice is one of
/// speed. Forward mode wins for points of bodies, where the partials
/// multiply out every rotation of the chain; the partials win for short
/// polynomial constraints, which they leave as the textbook writes them.
fn cheaper_bias(
    g: &mut crate::expr::Graph,
    factorer: &mut Factorer,
    (mass, forces, a): (&[Vec<Id>], &[Id], &[Vec<Id>]),
    partials: &[Id],
    structured: &[Id],
) -> Vec<Id> {
    let mut context = pieces(mass, forces, a);
    let mut chosen = Vec::with_capacity(partials.len());
    for (&old, &new) in partials.iter().zip(structured) {
        let f_old = factorer.factor(g, old);
        let (pick, factored) = if old == new {
            (old, f_old)
        } else {
            let f_new = factorer.factor(g, new);
            let mut cost = |g: &crate::expr::Graph, id: Id| {
                context.push(id);
                let ops = crate::expr::squares::operations(g, &context);
                context.pop();
                ops
            };
            if cost(g, f_new) < cost(g, f_old) {
                (new, f_new)
            } else {
                (old, f_old)
            }
        };
        context.push(factored);
        chosen.push(pick);
    }
    chosen
}

/// Every row of `b` factored, as a sum of squares where that costs at least
/// three operations fewer, counted with `M`, `F`, `A` and the other rows.
fn complete_squares(
    g: &mut crate::expr::Graph,
    factorer: &mut Factorer,
    mass: &[Vec<Id>],
    forces: &[Id],
    a: &[Vec<Id>],
    b: &[Id],
) -> Vec<Id> {
    let mut rows = factorer.factor_all(g, b);
    let shared = pieces(mass, forces, a);
    for i in 0..b.len() {
        let context: Vec<Id> = shared
            .iter()
            .chain(rows.iter().take(i))
            .chain(rows.iter().skip(i + 1))
            .copied()
            .collect();
        rows[i] = crate::expr::squares::complete(g, factorer, b[i], &context);
    }
    rows
}
