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
//! `q̈` and `λ` at run time.

use crate::diff::Differentiator;
use crate::expr::{Graph, Id, Sym};

/// The derivatives of `F`, `M`, `A` and `b`, column by column of the
/// Jacobian: `q₁ … qₙ, q̇₁ … q̇ₙ, u₁ … u_m`.
pub struct Tangent {
    /// The variable of each column.
    pub columns: Vec<Sym>,
    /// `∂Fᵢ/∂v`, `[column][i]`.
    pub forces: Vec<Vec<Id>>,
    /// The nonzero `∂Mᵢⱼ/∂v` as `(i, j, id)`, per column (`M` has no
    /// velocities or inputs, so only coordinate columns have any).
    pub mass: Vec<Vec<(usize, usize, Id)>>,
    /// The nonzero `∂Aᵣᵢ/∂v` as `(r, i, id)`, per column.
    pub a: Vec<Vec<(usize, usize, Id)>>,
    /// `∂bᵣ/∂v`, `[column][r]`.
    pub b: Vec<Vec<Id>>,
    /// `∂ψᵣ/∂qⱼ` of the velocity-level constraints `ψ` (`φ̇` or `φ`),
    /// `[r][j]`: how a change of the coordinates moves the velocities the
    /// constraints allow (the reduced linearization).
    pub velocity_constraints: Vec<Vec<Id>>,
}

/// What is differentiated: the pieces of the derived equations.
pub struct Pieces<'a> {
    /// `M`.
    pub mass: &'a [Vec<Id>],
    /// `F`.
    pub forces: &'a [Id],
    /// `A`.
    pub a: &'a [Vec<Id>],
    /// `b`.
    pub b: &'a [Id],
    /// `ψ`, the constraints at velocity level.
    pub velocity_constraints: &'a [Id],
}

/// Differentiates `F`, `M`, `A`, `b` by every column variable (`q₁ … qₙ`,
/// `q̇₁ … q̇ₙ`, then `inputs`) and `ψ` by the coordinates.
pub fn tangent(g: &mut Graph, p: &Pieces, inputs: &[Sym]) -> Tangent {
    let n = p.forces.len();
    let columns: Vec<Sym> = (0..n)
        .map(Sym::Coord)
        .chain((0..n).map(Sym::Vel))
        .chain(inputs.iter().copied())
        .collect();
    let mut d = Differentiator::new();
    // Differentiate every node below the roots in arena order first, so
    // that the memoised recursion of `partial` is one level deep however
    // deep the expressions are.
    let mut roots: Vec<Id> = p.forces.to_vec();
    roots.extend(p.mass.iter().flatten());
    roots.extend(p.a.iter().flatten());
    roots.extend(p.b);
    roots.extend(p.velocity_constraints);
    let order = g.reachable(&roots);
    for &v in &columns {
        for &id in &order {
            d.partial(g, id, v);
        }
    }
    let mut t = Tangent {
        columns: columns.clone(),
        forces: Vec::new(),
        mass: Vec::new(),
        a: Vec::new(),
        b: Vec::new(),
        velocity_constraints: Vec::new(),
    };
    t.velocity_constraints = p
        .velocity_constraints
        .iter()
        .map(|&psi| (0..n).map(|j| d.partial(g, psi, Sym::Coord(j))).collect())
        .collect();
    for &v in &columns {
        t.forces
            .push(p.forces.iter().map(|&f| d.partial(g, f, v)).collect());
        let mut mass = Vec::new();
        for (i, row) in p.mass.iter().enumerate() {
            for (j, &m) in row.iter().enumerate() {
                let dm = d.partial(g, m, v);
                if !g.is_zero(dm) {
                    mass.push((i, j, dm));
                }
            }
        }
        t.mass.push(mass);
        let mut a = Vec::new();
        for (r, row) in p.a.iter().enumerate() {
            for (i, &e) in row.iter().enumerate() {
                let da = d.partial(g, e, v);
                if !g.is_zero(da) {
                    a.push((r, i, da));
                }
            }
        }
        t.a.push(a);
        t.b.push(p.b.iter().map(|&e| d.partial(g, e, v)).collect());
    }
    t
}
