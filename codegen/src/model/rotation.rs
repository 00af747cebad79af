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
//! `ω` is `vee(Ṙ Rᵀ)`, `R` the body's attitude (body axes → world), built
//! as `J_ω q̇` from the joints' axes in the world
//! ([`crate::bodies::kinematics::angular_motion`]). The velocity of the
//! material point at `p` is `ȯ + ω × (p − o)`, `o` the body's origin:
//! unlike `velocity(body, [x, y, z])` the point need not be fixed in the
//! body (a wheel's contact point). An orientation lock's rows
//! are `½ vee(E − Eᵀ)` with `E = R_a R_bᵀ` (world axes): zero where the
//! attitudes agree, and their time derivative there is `ω_a − ω_b`, so the
//! rows' multipliers are the torque the lock exerts on `a` in world axes
//! (`−λ` on `b`). The rows also vanish at a half turn (`E` symmetric):
//! the lock holds an attitude near its target, as a projection keeps it.
//! The rows' rank drops there (to 1 of 3), so each row carries a branch
//! residual, `Eᵢᵢ − 1`: the three vanish together only where `E = I`, and
//! the states the rank of `A` is measured at are projected onto them too
//! (`crate::equations::partition`).
//!
//! A lock's rows of `A` and `b` come in closed form from the bodies'
//! angular velocities ([`crate::bodies::kinematics::angular_motion`]):
//! `φ̇ = B(E) ωₐ − B(Eᵀ) ω_b` with `B(X) = ½ ((tr X) 1 − X)`, exactly, by
//! `vee(Mᵀ ũ + ũ M) = ((tr M) 1 − M) u`. Differentiating φ twice instead
//! goes through the second partials of every entry of both rotation
//! matrices, about twice the operations on a humanoid's flat feet.

use super::lower::Lowerer;
use super::{HeldBody, Rates};
use crate::bodies::kinematics::{angular_motion, AngularMotion};
use crate::bodies::spatial::{self, M3, V3};
use crate::bodies::Placement;
use crate::expr::{Graph, Id};
use syn::Expr;

/// `B(X) = ½ ((tr X) 1 − X)`, each entry held.
fn half_trace_form(g: &mut Graph, x: &M3) -> M3 {
    let trace = g.add(&[x[0][0], x[1][1], x[2][2]]);
    let half = g.num(crate::expr::num::Num::Rational(1, 2));
    [0, 1, 2].map(|i| {
        [0, 1, 2].map(|j| {
            let e = if i == j {
                g.sub(trace, x[i][j])
            } else {
                g.neg(x[i][j])
            };
            let e = g.mul2(half, e);
            spatial::hold(g, e)
        })
    })
}

/// `Σₘ cₘ Jₘ` for the rows `J` of a 3 × n matrix: one row of `C J`.
fn combine(g: &mut Graph, c: &V3, j: &[Vec<Id>; 3]) -> Vec<Id> {
    (0..j[0].len())
        .map(|k| {
            let terms: Vec<Id> = (0..3).map(|m| g.mul2(c[m], j[m][k])).collect();
            g.add(&terms)
        })
        .collect()
}

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
    /// The index among the described bodies and the world frame of the
    /// body named by `body`.
    fn body_of(&mut self, body: &Expr) -> syn::Result<(usize, Placement)> {
        self.body_named(body, "rotations")
    }

    /// [`AngularMotion`] of the described body `i`.
    fn angular_motion(&mut self, i: usize) -> AngularMotion {
        let world: Vec<Placement> = self.frames.iter().map(|(_, p)| *p).collect();
        angular_motion(self.graph, (&self.described, &world), i, self.n)
    }

    /// Every body held at three or more of its points under a free base,
    /// each point numbers in the body's frame: its attitude and angular
    /// motion, for the velocity form's rows of the body
    /// (`crate::equations::held`, which decides whether the points fix
    /// the body).
    pub(super) fn held_bodies(&mut self, constraints: &[super::Constraint]) -> Vec<HeldBody> {
        let mut count: Vec<usize> = vec![0; self.frames.len()];
        for p in constraints.iter().filter_map(|c| c.in_base.as_ref()) {
            let numbers = p.local.iter().all(|&e| self.graph.as_num(e).is_some());
            if p.component == 0 && numbers {
                if let Some(c) = count.get_mut(p.body) {
                    *c += 1;
                }
            }
        }
        (0..count.len())
            .filter(|&i| count[i] >= 3)
            .map(|i| HeldBody {
                body: i,
                rotation: self.frames[i].1.rotation,
                angular: self.angular_motion(i),
            })
            .collect()
    }

    /// `angular_velocity(body)`: `ω = J_ω q̇` in world axes, `vee(Ṙ Rᵀ)`
    /// (`crate::bodies::kinematics::angular_motion`).
    pub fn angular_velocity(&mut self, e: &Expr, args: &[&Expr]) -> syn::Result<V3> {
        let [body] = args else {
            return Err(syn::Error::new_spanned(
                e,
                "expected `angular_velocity(body)`",
            ));
        };
        let (i, _) = self.body_of(body)?;
        Ok(self.angular_motion(i).velocity)
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

    /// `velocity(body, position(other, [..]))`: the velocity of the
    /// material point of the described body `i` (world frame `frame`) at
    /// the other point's place, `ȯ + ω × (p − o)`.
    pub fn velocity_at(&mut self, i: usize, frame: &Placement, place: &Expr) -> syn::Result<V3> {
        if call_named(place, "position").is_none() {
            return Err(syn::Error::new_spanned(
                place,
                "the point is `[x, y, z]` in the body's frame, or `position(other, [x, y, z])`",
            ));
        }
        let p = self.point(place)?;
        let offset = spatial::sub(self.graph, p, frame.translation);
        let omega = self.angular_motion(i).velocity;
        let mut d = crate::expr::diff::Differentiator::new();
        let origin = frame
            .translation
            .map(|x| d.time_derivative(self.graph, x, self.n).1);
        let turned = spatial::cross(self.graph, omega, offset);
        Ok(spatial::add(self.graph, origin, turned))
    }

    /// The three rows of `orientation(a) == orientation(b)` or
    /// `orientation(a) == [roll, pitch, yaw]`, each with its branch residual
    /// `Eᵢᵢ − 1` and its derivatives in closed form (`lock_rates`;
    /// module docs); `None` when `c` is not an orientation lock.
    pub fn orientation_rows(
        &mut self,
        c: &crate::parse::ConstraintInput,
    ) -> Option<Vec<(Id, Id, Option<Rates>)>> {
        let lhs = call_named(&c.lhs, "orientation")?;
        let usage = "an orientation lock is `orientation(a) == orientation(b)` or `orientation(a) == [roll, pitch, yaw]`";
        let a = match &lhs[..] {
            [body] => self.body_of(body),
            _ => Err(syn::Error::new_spanned(&c.lhs, usage)),
        };
        let target = match &c.rhs {
            Some(e) => match call_named(e, "orientation").as_deref() {
                Some([body]) => self.body_of(body).map(|(i, f)| (Some(i), f.rotation)),
                Some(_) => Err(syn::Error::new_spanned(e, usage)),
                None => self.attitude(e).map(|r| (None, r)),
            },
            None => Err(syn::Error::new_spanned(&c.tokens, usage)),
        };
        let ((a, frame), (b, target)) = match (a, target) {
            (Ok(a), Ok(t)) => (a, t),
            (a, t) => {
                for e in [a.err(), t.err()].into_iter().flatten() {
                    self.errors.push(e);
                }
                return Some(Vec::new());
            }
        };
        let e = spatial::mat_mul(self.graph, &frame.rotation, &spatial::transpose(&target));
        let e = e.map(|row| spatial::hold3(self.graph, row));
        let one = self.graph.int(1);
        let rows = self.vee(&e);
        let rates = self.lock_rates(&e, a, b);
        Some(
            rates
                .into_iter()
                .enumerate()
                .map(|(i, r)| (rows[i], self.graph.sub(e[i][i], one), r))
                .collect(),
        )
    }

    /// The rows' derivatives from the bodies' angular velocities: with
    /// `B(X) = ½ ((tr X) 1 − X)`, `Ė = ω̃ₐ E − E ω̃_b` and the identity
    /// `vee(Mᵀ ũ + ũ M) = ((tr M) 1 − M) u`,
    ///
    /// ```text
    /// φ̇ = B(E) ωₐ − B(Eᵀ) ω_b,     ∂φ̇/∂q̇ = B(E) Jₐ − B(Eᵀ) J_b,
    /// φ̈|q̈=0 = B(Ė) ωₐ + B(E) J̇ₐ q̇ − B(Ėᵀ) ω_b − B(Eᵀ) J̇_b q̇,
    /// ```
    ///
    /// `ω_b = 0` for an attitude of numbers. Exact: the same values as
    /// differentiating φ, without the partials of the rotation matrices.
    /// `None` for each row (the rows then differentiated as any other)
    /// where the described bodies were not recorded beside their frames,
    /// which `Lowerer::described` always does: never an index out of range.
    fn lock_rates(&mut self, e: &M3, a: usize, b: Option<usize>) -> [Option<Rates>; 3] {
        if self.described.len() != self.frames.len() {
            return [None, None, None];
        }
        let wa = self.angular_motion(a);
        let wb = b.map(|b| self.angular_motion(b));
        let g = &mut *self.graph;
        let zero = spatial::zero(g);
        let omega_b = wb.as_ref().map_or(zero, |m| m.velocity);
        let spin_a = spatial::skew(g, wa.velocity);
        let spin_b = spatial::skew(g, omega_b);
        let turned = spatial::mat_mul(g, &spin_a, e);
        let dragged = spatial::mat_mul(g, e, &spin_b);
        let rate: M3 = [0, 1, 2].map(|i| [0, 1, 2].map(|j| g.sub(turned[i][j], dragged[i][j])));
        let rate = rate.map(|row| spatial::hold3(g, row));
        let b_e = half_trace_form(g, e);
        let b_et = half_trace_form(g, &spatial::transpose(e));
        let b_rate = half_trace_form(g, &rate);
        let b_rate_t = half_trace_form(g, &spatial::transpose(&rate));
        let mut velocity = spatial::mat_vec(g, &b_e, wa.velocity);
        let mut bias = {
            let turning = spatial::mat_vec(g, &b_rate, wa.velocity);
            let accelerating = spatial::mat_vec(g, &b_e, wa.bias);
            spatial::add(g, turning, accelerating)
        };
        let mut rows: [Vec<Id>; 3] = [0, 1, 2].map(|i| combine(g, &b_e[i], &wa.jacobian));
        if let Some(wb) = &wb {
            let own = spatial::mat_vec(g, &b_et, wb.velocity);
            velocity = spatial::sub(g, velocity, own);
            let turning = spatial::mat_vec(g, &b_rate_t, wb.velocity);
            let accelerating = spatial::mat_vec(g, &b_et, wb.bias);
            let both = spatial::add(g, turning, accelerating);
            bias = spatial::sub(g, bias, both);
            for (i, row) in rows.iter_mut().enumerate() {
                let other = combine(g, &b_et[i], &wb.jacobian);
                for (x, y) in row.iter_mut().zip(other) {
                    *x = g.sub(*x, y);
                }
            }
        }
        let [x, y, z] = rows;
        [(0, x), (1, y), (2, z)].map(|(i, row)| {
            Some(Rates {
                velocity: velocity[i],
                row,
                bias: bias[i],
            })
        })
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
