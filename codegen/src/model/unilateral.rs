//! The `unilateral: [..]` section: gaps `g(q) ≥ 0` and their gradients
//! `∇g = ∂g/∂q`, for the generated `gaps`, `gap_jacobian` and `impact`
//! (the mathematics guide, `docs/math.md`, "Impacts").
//!
//! A gap is written `lhs >= rhs` (`g = lhs − rhs`) or `lhs <= rhs`
//! (`g = rhs − lhs`), so that the side that must stay apart reads as in a
//! textbook (`y >= 0`, `x <= wall`). It may use coordinates, parameters,
//! definitions and the bodies' points (`position(foot, [0, 0, -l]).z >= 0`),
//! and not:
//! - velocities: a gap is a distance; a velocity-dependent condition is an
//!   event, not a contact;
//! - time: Newton's law is applied to `∇g · q̇`, the approach velocity of a
//!   fixed obstacle; a moving one needs `∂g/∂t` in it, which is not done;
//! - control inputs: they are held over a step in `forces` only.

use super::lower::Lowerer;
use crate::expr::diff::Differentiator;
use crate::expr::{Id, Sym};
use crate::parse::List;
use proc_macro2::TokenStream;
use quote::ToTokens;
use syn::{BinOp, Expr};

/// One gap `g(q) ≥ 0`.
#[derive(Clone, Debug)]
pub struct Gap {
    /// `g(q)`, definitions substituted.
    pub gap: Id,
    /// `∂g/∂qⱼ`, one per coordinate.
    pub gradient: Vec<Id>,
    /// The gap as written, to span errors and print it.
    pub tokens: TokenStream,
}

impl Lowerer<'_> {
    /// The gaps of `unilateral: [..]`, checked, with their gradients; a
    /// malformed one is reported and left out.
    pub fn gaps(&mut self, list: &List<Expr>, first_input: usize) -> Vec<Gap> {
        let mut d = Differentiator::new();
        list.items
            .iter()
            .filter_map(|e| self.gap(e, first_input, &mut d))
            .collect()
    }

    fn gap(&mut self, e: &Expr, first_input: usize, d: &mut Differentiator) -> Option<Gap> {
        let tokens = e.to_token_stream();
        let (far, near) = match e {
            Expr::Binary(b) if matches!(b.op, BinOp::Ge(_)) => (&*b.left, &*b.right),
            Expr::Binary(b) if matches!(b.op, BinOp::Le(_)) => (&*b.right, &*b.left),
            _ => {
                self.errors.spanned(
                    e,
                    "a gap is written `expr >= expr` or `expr <= expr` (e.g. `y >= 0`)",
                );
                return None;
            }
        };
        let before = self.errors.count();
        let (far, near) = (self.lower(far), self.lower(near));
        if self.errors.count() != before {
            return None;
        }
        let gap = self.graph.sub(far, near);
        let g = &*self.graph;
        let rule = if g.mentions(gap, |s| matches!(s, Sym::Vel(_))) {
            Some("a gap may not depend on velocities (`dot(..)`): it is a distance `g(q) >= 0`")
        } else if g.mentions(gap, |s| s == Sym::Time) {
            Some("a gap may not depend on `t`: impacts are with fixed obstacles")
        } else if g.mentions(gap, |s| matches!(s, Sym::Param(i) if i >= first_input)) {
            Some("a gap may not depend on control inputs (`inputs` appear in `forces` only)")
        } else if !g.mentions(gap, |s| matches!(s, Sym::Coord(_))) {
            Some("a gap must involve at least one coordinate")
        } else {
            None
        };
        if let Some(message) = rule {
            self.errors.spanned(e, message);
            return None;
        }
        let gradient = (0..self.n)
            .map(|j| d.partial(self.graph, gap, Sym::Coord(j)))
            .collect();
        Some(Gap {
            gap,
            gradient,
            tokens,
        })
    }
}
