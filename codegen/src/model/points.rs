//! Points of bodies in expressions: `position(body, [x, y, z])` is the
//! world position of the point fixed at `[x, y, z]` in the body's frame,
//! `velocity(body, [x, y, z])` its velocity; `.x`, `.y`, `.z` pick a
//! component, and a constraint between two points (or a point and
//! `[x, y, z]`) is three rows. Rotations (`angular_velocity`, the velocity
//! of a body's point at another point's place, orientation locks) are in
//! `super::rotation`.

use super::bodies::single_ident;
use super::lower::Lowerer;
use crate::bodies::point_motion::PathColumn;
use crate::bodies::spatial::{self, V3};
use crate::bodies::Placement;
use crate::expr::{Id, Sym};
use syn::Expr;

/// A point under a free base, as [`crate::model::InBase`] records it for
/// each of its three rows.
#[derive(Clone)]
pub struct InBasePoint {
    /// The base's quaternion's `w` coordinate.
    pub w: usize,
    /// The base's `x` coordinate.
    pub x: usize,
    /// The point in the base's axes.
    pub point: V3,
    /// The body, by its index among the described bodies.
    pub body: usize,
    /// The point in the body's frame.
    pub local: V3,
    /// The columns of the joints between the base and the body
    /// (`crate::bodies::point_motion::path_columns`); `None` where one
    /// is not constant in its body's axes.
    pub path: Option<Vec<PathColumn>>,
}

impl Lowerer<'_> {
    /// `position(..).x` and the like.
    pub fn point_component(&mut self, field: &syn::ExprField) -> syn::Result<Id> {
        let axis = match &field.member {
            syn::Member::Named(m) if m == "x" => 0,
            syn::Member::Named(m) if m == "y" => 1,
            syn::Member::Named(m) if m == "z" => 2,
            _ => {
                return Err(syn::Error::new_spanned(
                    &field.member,
                    "a point's component is `.x`, `.y` or `.z`",
                ))
            }
        };
        Ok(self.point(&field.base)?[axis])
    }

    /// The world coordinates of a vector of a body: a row of
    /// `BODY_FUNCTIONS` (in `model/body_functions.rs`).
    pub fn point(&mut self, e: &Expr) -> syn::Result<V3> {
        match super::body_functions::body_function(e) {
            Some((f, call)) => {
                let args: Vec<&Expr> = call.args.iter().collect();
                (f.lower)(self, e, &args)
            }
            None => Err(syn::Error::new_spanned(
                e,
                super::body_functions::vector_usage(),
            )),
        }
    }

    /// The body named by `body` and its world frame.
    fn body_frame(&mut self, body: &Expr) -> syn::Result<(usize, Placement)> {
        self.body_named(body, "points")
    }

    /// The index among the described bodies and the world frame of the
    /// body named by `body`; without bodies, an error saying that `what`
    /// (points, rotations) of bodies need them.
    pub(super) fn body_named(
        &mut self,
        body: &Expr,
        what: &str,
    ) -> syn::Result<(usize, Placement)> {
        let Some(name) = single_ident(body) else {
            return Err(syn::Error::new_spanned(body, "expected a body's name"));
        };
        let Some(index) = self.frames.iter().position(|(n, _)| name == n) else {
            let why = if self.frames.is_empty() {
                format!("{what} of bodies need a `bodies` or `urdf` section")
            } else {
                format!("unknown body `{name}`")
            };
            return Err(syn::Error::new_spanned(body, why));
        };
        Ok((index, self.frames[index].1))
    }

    /// `[x, y, z]` of a point fixed in a body.
    fn local_point(&mut self, at: &Expr) -> syn::Result<V3> {
        self.triple(at, "the point").ok_or_else(|| {
            syn::Error::new_spanned(at, "the point is `[x, y, z]` in the body's frame")
        })
    }

    /// `position(body, [x, y, z])`: the world position of the point.
    pub fn position(&mut self, e: &Expr, args: &[&Expr]) -> syn::Result<V3> {
        let [body, at] = args else {
            return Err(syn::Error::new_spanned(
                e,
                "expected `position(body, [x, y, z])`",
            ));
        };
        let (index, _) = self.body_frame(body)?;
        let local = self.local_point(at)?;
        Ok(self.position_along_chain(index, local))
    }

    /// `velocity(body, [x, y, z])`: the world velocity of the point, the
    /// time derivative of its position; `velocity(body, position(..))`:
    /// `super::rotation`.
    pub fn point_velocity(&mut self, e: &Expr, args: &[&Expr]) -> syn::Result<V3> {
        let [body, at] = args else {
            return Err(syn::Error::new_spanned(
                e,
                "expected `velocity(body, [x, y, z])` or `velocity(body, position(other, [x, y, z]))`",
            ));
        };
        let (index, frame) = self.body_frame(body)?;
        if matches!(at, Expr::Call(_)) {
            return self.velocity_at(index, &frame, at);
        }
        let local = self.local_point(at)?;
        let turned = spatial::mat_vec(self.graph, &frame.rotation, local);
        let position = spatial::add(self.graph, frame.translation, turned);
        let mut d = crate::expr::diff::Differentiator::new();
        Ok(position.map(|p| d.time_derivative(self.graph, p, self.n).1))
    }

    /// `orientation(..)` where a vector is expected: it is one side of a lock.
    pub fn lock_only(&mut self, e: &Expr, _: &[&Expr]) -> syn::Result<V3> {
        Err(syn::Error::new_spanned(
            e,
            "`orientation(body)` is one side of a lock: `orientation(a) == orientation(b)` \
             or `orientation(a) == [roll, pitch, yaw]`",
        ))
    }

    /// The world position of the point `local` of body `index`, inside out
    /// along its chain of parent frames (`crate::bodies::parent_frames`):
    /// its derivatives are matrix–vector products, the world frame's would
    /// be matrix products.
    fn position_along_chain(&mut self, index: usize, local: V3) -> V3 {
        self.along_chain(index, local, false).0
    }

    /// The point `local` of body `index` carried up its chain of parent
    /// frames to the world, or with `to_base` up to the first free base
    /// on the way (whose `(w, x)` comes with it; without one, `None`).
    fn along_chain(
        &mut self,
        index: usize,
        local: V3,
        to_base: bool,
    ) -> (V3, Option<(usize, usize)>) {
        let mut point = local;
        let mut body = Some(index);
        // Each step moves to the parent, whose index is lower: at most
        // `chain.len()` steps.
        for _ in 0..self.chain.len() {
            let Some(i) = body else { break };
            if let Some(&Some(base)) = self.bases.get(i).filter(|_| to_base) {
                return (point, Some(base));
            }
            let Some(&(parent, frame)) = self.chain.get(i) else {
                break;
            };
            let turned = spatial::mat_vec(self.graph, &frame.rotation, point);
            point = spatial::add(self.graph, frame.translation, turned);
            point = spatial::hold3(self.graph, point);
            body = parent;
        }
        (point, None)
    }

    /// The point of `position(body, [x, y, z])` in the axes of the free
    /// base above the body, with the base's `(w, x)` coordinates, the
    /// body and the point in its frame ([`crate::model::InBase`]); `None`
    /// for any other expression, or a body with no free base above it.
    fn point_in_base(&mut self, e: &Expr) -> Option<InBasePoint> {
        let Expr::Call(call) = e else { return None };
        let args: Vec<&Expr> = call.args.iter().collect();
        let kind = single_ident(&call.func).map(ToString::to_string);
        let (Some("position"), [body, at]) = (kind.as_deref(), &args[..]) else {
            return None;
        };
        let name = single_ident(body)?;
        let index = self.frames.iter().position(|(n, _)| name == n)?;
        let local = self.triple(at, "the point")?;
        match self.along_chain(index, local, true) {
            (point, Some((w, x))) => Some(InBasePoint {
                w,
                x,
                point,
                body: index,
                local,
                path: self.path_below_base(index),
            }),
            (_, None) => None,
        }
    }

    /// The columns of the joints between body `index` and the free base
    /// above it, base first (`crate::bodies::point_motion::path_columns`).
    fn path_below_base(&mut self, index: usize) -> Option<Vec<PathColumn>> {
        let mut steps = Vec::new();
        let mut body = Some(index);
        // Each step moves to the parent, whose index is lower.
        for _ in 0..self.chain.len() {
            let i = body?;
            if let Some(Some(_)) = self.bases.get(i) {
                steps.reverse();
                return crate::bodies::point_motion::path_columns(self.graph, &steps);
            }
            let &(parent, frame) = self.chain.get(i)?;
            steps.push((frame, self.described.get(i)?.joint));
            body = parent;
        }
        None
    }

    /// The rows of a constraint between points, or `None` when it is not
    /// one; for `position(body, r) == [..]` (constant) on a body under a
    /// free base, also the point in the base's axes
    /// (`point_in_base`).
    pub fn point_rows(
        &mut self,
        c: &crate::parse::ConstraintInput,
    ) -> Option<(Vec<Id>, Option<InBasePoint>)> {
        let is_point = |e: &Expr| {
            super::body_functions::body_function(e)
                .is_some_and(|(f, _)| f.role == super::body_functions::Role::Vector)
        };
        if !is_point(&c.lhs) {
            return None;
        }
        let lhs = self.point(&c.lhs).map_err(|e| self.errors.push(e)).ok()?;
        let rhs = match &c.rhs {
            Some(e) if is_point(e) => self.point(e).map_err(|e| self.errors.push(e)).ok()?,
            Some(e @ Expr::Array(_)) => {
                let ids: Vec<Id> = match e {
                    Expr::Array(a) if a.elems.len() == 3 => {
                        a.elems.iter().map(|x| self.lower(x)).collect()
                    }
                    _ => {
                        self.errors
                            .spanned(e, "a point equals `[x, y, z]` or another point");
                        return Some((Vec::new(), None));
                    }
                };
                [ids[0], ids[1], ids[2]]
            }
            Some(e) => {
                self.errors
                    .spanned(e, "a point equals `[x, y, z]` or another point");
                return Some((Vec::new(), None));
            }
            None => {
                self.errors.spanned(
                    &c.tokens,
                    "a point alone is not a constraint: write `position(..) == [x, y, z]`",
                );
                return Some((Vec::new(), None));
            }
        };
        let constant = rhs.iter().all(|&e| {
            !self
                .graph
                .mentions(e, |s| matches!(s, Sym::Coord(_) | Sym::Vel(_) | Sym::Time))
        });
        let in_base = match &c.rhs {
            Some(Expr::Array(_)) if constant => self.point_in_base(&c.lhs),
            _ => None,
        };
        let rows = (0..3).map(|i| self.graph.sub(lhs[i], rhs[i])).collect();
        Some((rows, in_base))
    }
}
