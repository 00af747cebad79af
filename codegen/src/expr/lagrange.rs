//! Lagrange's equations from energies: `T(q, q̇, t)` at most quadratic in
//! `q̇`, `V(q, t)` and generalized forces `Q` give the unconstrained system
//! `M q̈ = F` that the rest of the pipeline takes unchanged:
//!
//! - `M = ∂²T/∂q̇∂q̇ᵀ`;
//! - `F = Q − ∂V/∂q + ∂T/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t`,
//!
//! from `d/dt(∂T/∂q̇) − ∂T/∂q = Q − ∂V/∂q` with
//! `d/dt(∂T/∂q̇ᵢ) = Σⱼ Mᵢⱼ q̈ⱼ + Σⱼ ∂²T/∂q̇ᵢ∂qⱼ q̇ⱼ + ∂²T/∂q̇ᵢ∂t`.
//! Used by the model stage, which checks the results like written input.

use crate::expr::diff::Differentiator;
use crate::expr::{Graph, Id, Node, Sym};
use std::fmt;

/// Why a kinetic energy has no mass matrix: it is not a polynomial of
/// degree at most 2 in the velocities.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotQuadratic {
    /// A velocity occurs where no polynomial has one: under a function
    /// (`abs`, `max`, `signum`, …), under a fractional power (`sqrt`,
    /// `hypot`, `powf(2.5)`), in a denominator, or in a variable exponent.
    /// The text names the construct.
    NotPolynomial(String),
    /// A polynomial in the velocities with a term of this degree (> 2)
    /// whose coefficient is not identically zero.
    Degree(u32),
}

impl fmt::Display for NotQuadratic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NotQuadratic::NotPolynomial(what) => write!(f, "a velocity occurs {what}"),
            NotQuadratic::Degree(d) => write!(f, "it has a term of degree {d} in them"),
        }
    }
}

/// `M = ∂²T/∂q̇∂q̇ᵀ` (upper triangle mirrored), or why there is none: `T`
/// must be a polynomial of degree at most 2 in the velocities, whose
/// coefficients may be anything of `q`, `t` and the parameters.
///
/// Decided exactly on the expression ([`velocity_degree`]), not by sampling:
/// a velocity under a function, a fractional or negative power or a
/// variable exponent is rejected wherever it occurs (`|ẋ|·ẋ` looks
/// quadratic at positive velocities, `max(x − 5, 0)·ẋ⁴` at small `x`),
/// and so is a term of degree 3 or more, however small its coefficient
/// (`1e-12·ẋ⁴`), unless the terms of degree above 2 cancel symbolically
/// (every third derivative in the velocities simplifies to zero).
pub fn mass_from_kinetic_energy(
    g: &mut Graph,
    d: &mut Differentiator,
    kinetic: Id,
    n: usize,
) -> Result<Vec<Vec<Id>>, NotQuadratic> {
    let degree = velocity_degree(g, kinetic)?;
    if degree > 2 && !higher_terms_cancel(g, d, kinetic, n) {
        return Err(NotQuadratic::Degree(degree));
    }
    let zero = g.int(0);
    let mut m = vec![vec![zero; n]; n];
    #[allow(clippy::needless_range_loop)] // (i, j) and (j, i): indices read best
    for i in 0..n {
        let first = d.partial(g, kinetic, Sym::Vel(i));
        for j in i..n {
            let entry = d.partial(g, first, Sym::Vel(j));
            // A polynomial of degree ≤ 2 has velocity-free second
            // derivatives; a form that still mentions a velocity (terms
            // that cancel only in value) is that constant, read at zero
            // velocity, where it is defined: no velocity divides.
            let entry = if g.mentions(entry, |s| matches!(s, Sym::Vel(_))) {
                g.substitute(entry, &|s| matches!(s, Sym::Vel(_)).then_some(zero))
            } else {
                entry
            };
            m[i][j] = entry;
        }
    }
    // Written symmetric: the identities (`expr::trig`) are applied with the
    // forces, on the set `q̈` is computed from.
    #[allow(clippy::needless_range_loop)] // (i, j) and (j, i): indices read best
    for i in 0..n {
        for j in 0..i {
            m[i][j] = m[j][i];
        }
    }
    Ok(m)
}

/// The degree of `e` as a polynomial in the velocities, read off its
/// structure (an upper bound where terms of a sum cancel in value only;
/// saturating), or why it is none: every velocity must stand in sums and in
/// products under non-negative integer powers, never inside a function, a
/// fractional or negative power, or a variable exponent. Coefficients (the
/// subexpressions without velocities) may be anything.
pub fn velocity_degree(g: &Graph, e: Id) -> Result<u32, NotQuadratic> {
    let order = g.reachable(&[e]);
    let mut degree: Vec<u32> = vec![0; g.len()];
    for &id in &order {
        let of = |c: Id| degree[c.index()];
        let value = match g.node(id) {
            Node::Num(_) => 0,
            Node::Sym(s) => u32::from(matches!(s, Sym::Vel(_))),
            Node::Add(terms, _) => terms.iter().map(|&(t, _)| of(t)).max().unwrap_or(0),
            Node::Mul(factors) => {
                let mut total = 0u32;
                for &(b, p) in factors.iter() {
                    if of(b) == 0 {
                        continue;
                    }
                    let power = match p.as_integer() {
                        Some(k) if k > 0 => u32::try_from(k).unwrap_or(u32::MAX),
                        Some(_) => {
                            return Err(NotQuadratic::NotPolynomial(
                                "in a denominator (a negative power)".into(),
                            ))
                        }
                        None => {
                            return Err(NotQuadratic::NotPolynomial(format!(
                                "under the fractional power {p} (`sqrt`, `hypot`, `powf`)"
                            )))
                        }
                    };
                    total = total.saturating_add(of(b).saturating_mul(power));
                }
                total
            }
            Node::Pow([b, x]) => {
                if of(*b) > 0 || of(*x) > 0 {
                    return Err(NotQuadratic::NotPolynomial(
                        "in a power with a variable exponent (`powf`)".into(),
                    ));
                }
                0
            }
            Node::Func(f, args) => {
                if args.as_slice().iter().any(|&a| of(a) > 0) {
                    return Err(NotQuadratic::NotPolynomial(format!(
                        "under the function `{}`",
                        f.name()
                    )));
                }
                0
            }
        };
        degree[id.index()] = value;
    }
    Ok(degree[e.index()])
}

/// Whether every third partial derivative of the polynomial `t` in the
/// velocities simplifies to zero, i.e. its terms of degree above 2 cancel.
fn higher_terms_cancel(g: &mut Graph, d: &mut Differentiator, t: Id, n: usize) -> bool {
    for i in 0..n {
        let first = d.partial(g, t, Sym::Vel(i));
        for j in i..n {
            let second = d.partial(g, first, Sym::Vel(j));
            for k in j..n {
                let third = d.partial(g, second, Sym::Vel(k));
                let third = g.distribute(third);
                if !g.is_zero(third) {
                    return false;
                }
            }
        }
    }
    true
}

/// `F = Q − ∂V/∂q + ∂T/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t`; `kinetic` absent
/// when `M` was written directly (then `F = Q − ∂V/∂q`). As derived: the
/// caller applies the trigonometric identities (`expr::trig`), with `M`
/// where `M` comes from `T`.
pub fn forces(
    g: &mut Graph,
    d: &mut Differentiator,
    kinetic: Option<Id>,
    potential: Option<Id>,
    applied: &[Id],
) -> Vec<Id> {
    let n = applied.len();
    let sums: Vec<Id> = (0..n)
        .map(|i| {
            let mut terms = vec![applied[i]];
            if let Some(v) = potential {
                let dv = d.partial(g, v, Sym::Coord(i));
                terms.push(g.neg(dv));
            }
            if let Some(t) = kinetic {
                terms.push(d.partial(g, t, Sym::Coord(i)));
                let momentum = d.partial(g, t, Sym::Vel(i));
                for j in 0..n {
                    let coupling = d.partial(g, momentum, Sym::Coord(j));
                    let qd = g.sym(Sym::Vel(j));
                    let term = g.mul2(coupling, qd);
                    terms.push(g.neg(term));
                }
                let explicit = d.partial(g, momentum, Sym::Time);
                terms.push(g.neg(explicit));
            }
            // Distributed, so that the terms of ∂T/∂q and of the coupling
            // (∂²T/∂q̇∂qᵀ) q̇ that cancel do (the cart-pole's θ equation).
            let terms: Vec<Id> = terms.into_iter().map(|t| g.distribute(t)).collect();
            g.add(&terms)
        })
        .collect();
    sums
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::num::Num;

    /// A pendulum of length 1 in its angle: `T = θ̇²/2`, `V = −cos θ`:
    /// `M = 1`, `F = −sin θ`.
    #[test]
    fn pendulum_in_its_angle() {
        let mut g = Graph::new();
        let mut d = Differentiator::new();
        let (th, thd) = (g.sym(Sym::Coord(0)), g.sym(Sym::Vel(0)));
        let t = g.pown(thd, Num::int(2));
        let t = g.scale(t, Num::ratio(1, 2));
        let cos = g.func(crate::expr::Func::Cos, th);
        let v = g.neg(cos);
        let m = mass_from_kinetic_energy(&mut g, &mut d, t, 1).expect("quadratic");
        assert_eq!(g.as_num(m[0][0]), Some(Num::ONE));
        let zero = g.int(0);
        let f = forces(&mut g, &mut d, Some(t), Some(v), &[zero]);
        let sin = g.func(crate::expr::Func::Sin, th);
        assert_eq!(f[0], g.neg(sin));
    }

    /// `T = ẋ³` is not quadratic: no mass matrix.
    #[test]
    fn cubic_kinetic_energy_has_no_mass_matrix() {
        let mut g = Graph::new();
        let xd = g.sym(Sym::Vel(0));
        let t = g.pown(xd, Num::int(3));
        assert_eq!(
            mass_from_kinetic_energy(&mut g, &mut Differentiator::new(), t, 1),
            Err(NotQuadratic::Degree(3))
        );
    }
}
