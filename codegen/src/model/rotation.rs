//! Rotations of bodies in expressions and constraints (with `bodies` or
//! `urdf`): a body's angular velocity, the velocity of the body's material
//! point at a place given by another point, and orientation locks.
//!
//! ```text
//! angular_velocity(disc).z                      // ω in world axes
//! velocity(disc, position(tilt, [0, 0, 0])).x   // the disc's point now at that place
//! orientation(a) == orientation(b)              // three rows: a welded to b in attitude
//! orientation(a) == [roll, pitch, yaw]          // a's axes held at Rz(yaw) Ry(pitch) Rx(roll)
//! ```
//!
//! `ω` is `vee(Ṙ Rᵀ)`, `R` the body's attitude (body axes → world). The
//! velocity of the material point at `p` is `ȯ + Ṙ Rᵀ (p − o)`, `o` the
//! body's origin: unlike `velocity(body, [x, y, z])` the point need not be
//! fixed in the body (a wheel's contact point). An orientation lock's rows
//! are `½ vee(E − Eᵀ)` with `E = R_a R_bᵀ` (world axes): zero where the
//! attitudes agree, and their time derivative there is `ω_a − ω_b`, so the
//! rows' multipliers are the torque the lock exerts on `a` in world axes
//! (`−λ` on `b`). The rows also vanish at a half turn (`E` symmetric):
//! the lock holds an attitude near its target, as a projection keeps it.
//! The rows' rank drops there (to 1 of 3), so each row carries a branch
//! residual, `Eᵢᵢ − 1`: the three vanish together only where `E = I`, and
//! the states the rank of `A` is measured at are projected onto them too
//! (`crate::equations::partition`).

use super::lower::Lowerer;
use crate::bodies::spatial::{self, M3, V3};
use crate::bodies::Placement;
use crate::expr::Id;
use syn::Expr;

fn name_of(e: &Expr) -> Option<&syn::Ident> {
    match e {
        Expr::Path(p) if p.qself.is_none() && p.attrs.is_empty() => p.path.get_ident(),
        _ => None,
    }
}

/// `f(args)` as a call of the DSL function named `f`, or `None`.
pub fn call_named<'e>(e: &'e Expr, f: &str) -> Option<Vec<&'e Expr>> {
    match e {
        Expr::Call(call) if name_of(&call.func).is_some_and(|n| n == f) => {
            Some(call.args.iter().collect())
        }
        _ => None,
    }
}

impl Lowerer<'_> {
    /// The world frame of the body named by `body`.
    pub fn frame_of(&mut self, body: &Expr) -> syn::Result<Placement> {
        let Some(name) = name_of(body) else {
            return Err(syn::Error::new_spanned(body, "expected a body's name"));
        };
        match self.frames.iter().find(|(n, _)| name == n) {
            Some(f) => Ok(f.1),
            None if self.frames.is_empty() => Err(syn::Error::new_spanned(
                body,
                "rotations of bodies need a `bodies` or `urdf` section",
            )),
            None => Err(syn::Error::new_spanned(
                body,
                format!("unknown body `{name}`"),
            )),
        }
    }

    /// The time derivative of each entry of `m`.
    fn rate(&mut self, m: &M3) -> M3 {
        let mut d = crate::expr::diff::Differentiator::new();
        m.map(|row| row.map(|x| d.time_derivative(self.graph, x, self.n).1))
    }

    /// `angular_velocity(body)`: `vee(Ṙ Rᵀ)`, world axes.
    pub fn angular_velocity(&mut self, e: &Expr, args: &[&Expr]) -> syn::Result<V3> {
        let [body] = args else {
            return Err(syn::Error::new_spanned(
                e,
                "expected `angular_velocity(body)`",
            ));
        };
        let frame = self.frame_of(body)?;
        let rate = self.rate(&frame.rotation);
        let spin = spatial::mat_mul(self.graph, &rate, &spatial::transpose(&frame.rotation));
        Ok(self.vee(&spin))
    }

    /// `vee` of a skew-symmetric matrix, as `½ (M − Mᵀ)`'s axial vector.
    fn vee(&mut self, m: &M3) -> V3 {
        let two = self.graph.int(2);
        let mut axial = |i: usize, j: usize| {
            let d = self.graph.sub(m[i][j], m[j][i]);
            self.graph.div(d, two)
        };
        [axial(2, 1), axial(0, 2), axial(1, 0)]
    }

    /// `velocity(body, position(other, [..]))`: the velocity of `body`'s
    /// material point at the other point's place, `ȯ + Ṙ Rᵀ (p − o)`.
    pub fn velocity_at(&mut self, frame: &Placement, place: &Expr) -> syn::Result<V3> {
        if call_named(place, "position").is_none() {
            return Err(syn::Error::new_spanned(
                place,
                "the point is `[x, y, z]` in the body's frame, or `position(other, [x, y, z])`",
            ));
        }
        let p = self.point(place)?;
        let offset = spatial::sub(self.graph, p, frame.translation);
        let local = spatial::mat_t_vec(self.graph, &frame.rotation, offset);
        let rate = self.rate(&frame.rotation);
        let mut d = crate::expr::diff::Differentiator::new();
        let origin = frame
            .translation
            .map(|x| d.time_derivative(self.graph, x, self.n).1);
        let turned = spatial::mat_vec(self.graph, &rate, local);
        Ok(spatial::add(self.graph, origin, turned))
    }

    /// The three rows of `orientation(a) == orientation(b)` or
    /// `orientation(a) == [roll, pitch, yaw]`, each with its branch residual
    /// `Eᵢᵢ − 1` (module docs); `None` when `c` is not an orientation lock.
    pub fn orientation_rows(&mut self, c: &crate::parse::ConstraintInput) -> Option<Vec<(Id, Id)>> {
        let lhs = call_named(&c.lhs, "orientation")?;
        let usage = "an orientation lock is `orientation(a) == orientation(b)` or `orientation(a) == [roll, pitch, yaw]`";
        let a = match &lhs[..] {
            [body] => self.frame_of(body),
            _ => Err(syn::Error::new_spanned(&c.lhs, usage)),
        };
        let target = match &c.rhs {
            Some(e) => match call_named(e, "orientation").as_deref() {
                Some([body]) => self.frame_of(body).map(|f| f.rotation),
                Some(_) => Err(syn::Error::new_spanned(e, usage)),
                None => self.attitude(e),
            },
            None => Err(syn::Error::new_spanned(&c.tokens, usage)),
        };
        let (a, target) = match (a, target) {
            (Ok(a), Ok(t)) => (a, t),
            (a, t) => {
                for e in [a.err(), t.err()].into_iter().flatten() {
                    self.errors.push(e);
                }
                return Some(Vec::new());
            }
        };
        let e = spatial::mat_mul(self.graph, &a.rotation, &spatial::transpose(&target));
        let one = self.graph.int(1);
        let rows = self.vee(&e);
        Some(
            (0..3)
                .map(|i| (rows[i], self.graph.sub(e[i][i], one)))
                .collect(),
        )
    }

    /// `[roll, pitch, yaw]` of numbers and parameters: `Rz Ry Rx`.
    fn attitude(&mut self, e: &Expr) -> syn::Result<M3> {
        let Expr::Array(array) = e else {
            return Err(syn::Error::new_spanned(
                e,
                "an attitude is `[roll, pitch, yaw]` or `orientation(body)`",
            ));
        };
        if array.elems.len() != 3 {
            return Err(syn::Error::new_spanned(e, "an attitude has 3 angles"));
        }
        let ids: Vec<Id> = array.elems.iter().map(|x| self.lower(x)).collect();
        let moving = ids.iter().any(|&id| {
            self.graph.mentions(id, |s| {
                matches!(
                    s,
                    crate::expr::Sym::Coord(_) | crate::expr::Sym::Vel(_) | crate::expr::Sym::Time
                )
            })
        });
        if moving {
            return Err(syn::Error::new_spanned(
                e,
                "the attitude of a lock may use numbers and parameters, not coordinates, velocities or `t`",
            ));
        }
        Ok(spatial::rpy(self.graph, [ids[0], ids[1], ids[2]]))
    }
}
