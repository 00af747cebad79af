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

use crate::diff::Differentiator;
use crate::expr::{Graph, Id, Sym};
use crate::rng::SplitMix64;

/// `∂²T/∂q̇∂q̇ᵀ` (upper triangle mirrored), or `None` when it still depends
/// on the velocities, i.e. `T` is not at most quadratic in them (checked
/// numerically at a few pseudo-random points; a symbolic form that cancels
/// to a velocity-free value is then evaluated with the velocities at zero).
pub fn mass_from_kinetic_energy(
    g: &mut Graph,
    d: &mut Differentiator,
    kinetic: Id,
    n: usize,
) -> Option<Vec<Vec<Id>>> {
    let zero = g.int(0);
    let mut m = vec![vec![zero; n]; n];
    #[allow(clippy::needless_range_loop)] // (i, j) and (j, i): indices read best
    for i in 0..n {
        let first = d.partial(g, kinetic, Sym::Vel(i));
        for j in i..n {
            let entry = d.partial(g, first, Sym::Vel(j));
            let entry = velocity_free(g, entry)?;
            m[i][j] = entry;
            m[j][i] = entry;
        }
    }
    Some(m)
}

/// `e` with the velocities set to zero, when its value does not depend on
/// them (else `None`).
fn velocity_free(g: &mut Graph, e: Id) -> Option<Id> {
    if !g.mentions(e, |s| matches!(s, Sym::Vel(_))) {
        return Some(e);
    }
    let mut rng = SplitMix64::new(0x7e57_ab1e);
    for _ in 0..4 {
        let (a, b) = (rng.next_u64(), rng.next_u64());
        // The same positions, time and parameters; different velocities.
        let at = |velocities: u64| {
            move |s: Sym| match s {
                Sym::Vel(_) => SplitMix64::value_for(velocities, s),
                _ => SplitMix64::value_for(a, s),
            }
        };
        let (x, y) = (g.eval(&[e], &at(a))[0], g.eval(&[e], &at(b))[0]);
        if x.is_finite() && y.is_finite() && (x - y).abs() > 1e-9 * x.abs().max(y.abs()).max(1.0) {
            return None;
        }
    }
    let zero = g.int(0);
    Some(g.substitute(e, &|s| matches!(s, Sym::Vel(_)).then_some(zero)))
}

/// `F = Q − ∂V/∂q + ∂T/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t`; `kinetic` absent
/// when `M` was written directly (then `F = Q − ∂V/∂q`).
pub fn forces(
    g: &mut Graph,
    d: &mut Differentiator,
    kinetic: Option<Id>,
    potential: Option<Id>,
    applied: &[Id],
) -> Vec<Id> {
    let n = applied.len();
    (0..n)
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
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::num::Num;

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
        assert!(mass_from_kinetic_energy(&mut g, &mut Differentiator::new(), t, 1).is_none());
    }
}
