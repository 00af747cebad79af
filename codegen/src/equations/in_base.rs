//! The rows `position(body, r) == c` of a body under a free base, in the
//! base's axes (`crate::model::InBase`). With the base at `p`, turned by
//! `R̂ = R(q/|q|)` with the body angular velocity `ω = 2 G q̇ / |q|²`
//! (`crate::bodies::free`), and `r(q)` the point in the base's axes (a
//! function of the joints between), the three rows are
//! `φ = p + R̂ r − c`, and
//!
//! ```text
//! R̂ᵀ φ̈ = z + β × r + J q̈ + ω × (ω × r) + 2 ω × ṙ + ä₀ − k (qᵀq̇) ω × r
//! ```
//!
//! in the velocity form's unknowns (`p̈ = R̂ z`, `q̈_quat = ½ (q α + Gᵀ β)`, so that
//! `ω̇ = β − k (qᵀq̇) ω`, `k = 2/|q|²`), where `J = ∂r/∂q`, `ṙ = J q̇` and
//! `ä₀ = D₀D₀ r` (the point's acceleration in the base with `q̈ = 0`).
//! Premultiplying the rows by `R̂ᵀ` (invertible: the multipliers are
//! `λ = R̂ λ'`) leaves them free of the attitude, with no quotient rule: `Ṙ̂ = R̂ ω̃` holds of the numbers wherever `q ≠ 0`. The
//! `α` column is zero (`R̂` is homogeneous of degree 0 in `q`).

use crate::bodies::free;
use crate::bodies::spatial::{self, V3};
use crate::expr::diff::{AtRest, Differentiator};
use crate::expr::{Graph, Id, Sym};
use crate::model::Constraint;

/// Three rows of one point under a free base, premultiplied by `R̂ᵀ`.
#[derive(Clone, Debug)]
pub struct InBaseRows {
    /// The model's rows, `x`, `y`, `z`.
    pub rows: [usize; 3],
    /// `R̂ᵀ A T`, three rows over the velocity form's `n` unknowns.
    pub a: [Vec<Id>; 3],
    /// `R̂ᵀ b`.
    pub b: [Id; 3],
    /// The base's `x` coordinate: its `R̂` (`crate::equations::velocity`'s
    /// `free`) turns the multipliers back, `λ = R̂ λ'`, and a correction
    /// `δb` of the rows enters as `R̂ᵀ δb`.
    pub base: usize,
    /// The base's quaternion's `w` coordinate.
    pub w: usize,
    /// The model's own rows of `A` (in `q̇`), in the same closed form:
    /// `I` for the position, `R̂ ((k Gₘ) × r)` for the quaternion's `q̇ₘ`,
    /// `R̂ J` for the joints between.
    pub model_a: [Vec<Id>; 3],
    /// The model's own `b = R̂ (R̂ᵀ b)`.
    pub model_b: [Id; 3],
    /// The body the point is fixed in, by its index among the described
    /// bodies, and the point in its frame.
    pub body: (usize, V3),
    /// `r`, the point in the base's axes.
    pub point: V3,
    /// The columns of the joints between the base and the body
    /// (`crate::bodies::point_motion`); `None` where one is not constant
    /// in its body's axes.
    pub path: Option<Vec<crate::bodies::point_motion::PathColumn>>,
}

/// Every complete triple of rows of one point under a free base, in the
/// base's axes.
pub fn rows(g: &mut Graph, constraints: &[Constraint], n: usize) -> Vec<InBaseRows> {
    let mut out = Vec::new();
    let mut d = Differentiator::new();
    let mut at_rest = AtRest::default();
    for r in 0..constraints.len().saturating_sub(2) {
        let triple = [r, r + 1, r + 2].map(|i| constraints[i].in_base.as_ref());
        let [Some(x), Some(y), Some(z)] = triple else {
            continue;
        };
        let same = |o: &crate::model::InBase| o.w == x.w && o.x == x.x && o.point == x.point;
        if [x.component, y.component, z.component] != [0, 1, 2] || !same(y) || !same(z) {
            continue;
        }
        if x.w + 4 > n || x.x + 3 > n {
            continue;
        }
        out.push(triple_rows(
            g,
            (&mut d, &mut at_rest),
            x,
            [r, r + 1, r + 2],
            n,
        ));
    }
    out
}

/// The base's attitude and angular velocity, from its quaternion.
pub(super) struct Turning {
    /// The quaternion `q`.
    pub(super) q: [Id; 4],
    /// `q̇`.
    pub(super) rates: [Id; 4],
    /// `G(q)`.
    pub(super) big_g: [[Id; 4]; 3],
    /// `k = 2/|q|²`.
    pub(super) k: Id,
    /// `ω = k G q̇`, held.
    pub(super) omega: V3,
}

impl Turning {
    /// `−κ = −k (qᵀq̇)`: how fast `ω`'s scale shrinks as the quaternion's
    /// norm grows (`ω̇ = β − κ ω`).
    pub(super) fn minus_kappa(&self, g: &mut Graph) -> Id {
        let dot: Vec<Id> = (self.q.iter().zip(&self.rates))
            .map(|(&a, &b)| g.mul2(a, b))
            .collect();
        let dot = g.add(&dot);
        let minus = g.int(-1);
        g.mul(&[minus, self.k, dot])
    }
}

/// [`Turning`] of the base whose quaternion's `w` is `w`.
pub(super) fn turning(g: &mut Graph, w: usize) -> Turning {
    let q = free::coordinates(g, w);
    let rates = [0, 1, 2, 3].map(|k| g.sym(Sym::Vel(w + k)));
    let big_g = free::g_matrix(g, q);
    let k = free::twice_inverse_norm(g, q);
    let omega: V3 = big_g.map(|row| {
        let terms: Vec<Id> = row
            .iter()
            .zip(&rates)
            .map(|(&a, &b)| g.mul2(a, b))
            .collect();
        let sum = g.add(&terms);
        let w = g.mul2(k, sum);
        spatial::hold(g, w)
    });
    Turning {
        q,
        rates,
        big_g,
        k,
        omega,
    }
}

/// The three rows of one point: `R̂ᵀ A T` and `R̂ᵀ b` in the velocity
/// form's unknowns, and the model's own rows in the same closed form. The
/// nodes are made in one fixed order (`b`'s terms, `R̂`, `b`, `A`, then
/// the model's rows), which the canonical order of terms follows.
fn triple_rows(
    g: &mut Graph,
    (d, at_rest): (&mut Differentiator, &mut AtRest),
    base: &crate::model::InBase,
    rows: [usize; 3],
    n: usize,
) -> InBaseRows {
    let turning = turning(g, base.w);
    let terms = bias_terms(g, at_rest, &turning, base.point);
    let rotation = free::rotation(g, turning.q);
    let (zero, one) = (g.int(0), g.int(1));
    let b = [0, 1, 2].map(|i| {
        let sum = g.add(&terms.map(|t| t[i]));
        g.neg(sum)
    });
    let a = [0, 1, 2].map(|i| {
        let r = base.point;
        let mut row: Vec<Id> = (0..n).map(|j| d.partial(g, r[i], Sym::Coord(j))).collect();
        for j in 0..3 {
            // R̂ᵀ p̈ = z: the position's accelerations in the base's axes.
            row[base.x + j] = if i == j { one } else { zero };
            let mut unit = [zero; 3];
            unit[j] = one;
            row[base.w + 1 + j] = spatial::cross(g, unit, r)[i];
        }
        row[base.w] = zero;
        row
    });
    let model_b = spatial::mat_vec(g, &rotation, b);
    let model_a = model_rows(g, (&rotation, &turning), base, &a);
    InBaseRows {
        rows,
        a,
        b,
        base: base.x,
        w: base.w,
        model_a,
        model_b,
        body: (base.body, base.local),
        point: base.point,
        path: base.path.clone(),
    }
}

/// The terms of `−R̂ᵀ b` besides `z`, `β × r` and `J q̈`:
/// `ω × (ω × r)`, `2 ω × ṙ`, `ä₀` and `−k (qᵀq̇) ω × r`.
fn bias_terms(g: &mut Graph, at_rest: &mut AtRest, turning: &Turning, r: V3) -> [V3; 4] {
    let omega = turning.omega;
    let velocity: V3 = r.map(|e| at_rest.derivative(g, e));
    let acceleration: V3 = velocity.map(|e| at_rest.derivative(g, e));
    // `ṙ` held where it multiplies ω: its sums' contents would otherwise
    // multiply every product.
    let held_velocity = spatial::hold3(g, velocity);
    let omega_r = spatial::cross(g, omega, r);
    let centripetal = spatial::cross(g, omega, omega_r);
    let transport = spatial::cross(g, omega, held_velocity);
    let two = g.int(2);
    let transport = spatial::scale(g, two, transport);
    let scale = turning.minus_kappa(g);
    let norm_rate = spatial::scale(g, scale, omega_r);
    [centripetal, transport, acceleration, norm_rate]
}

/// The model's own rows of `A` (in `q̇`) in closed form, from the rows
/// `a` in the base's axes: `I` for the position, `R̂ ((k Gₘ) × r)` for the
/// quaternion's `q̇ₘ`, `R̂ J` for the joints between.
fn model_rows(
    g: &mut Graph,
    (rotation, turning): (&spatial::M3, &Turning),
    base: &crate::model::InBase,
    a: &[Vec<Id>; 3],
) -> [Vec<Id>; 3] {
    let n = a[0].len();
    let (zero, one) = (g.int(0), g.int(1));
    let turn = |g: &mut Graph, v: V3| spatial::mat_vec(g, rotation, v);
    // R̂ ((k Gₘ) × r) = (R̂ k Gₘ) × (R̂ r): the turned columns are the same
    // for every point of the base.
    let world_r = turn(g, base.point);
    let world_r = spatial::hold3(g, world_r);
    let mut model_a = [0, 1, 2].map(|_| vec![zero; n]);
    for j in 0..n {
        let column: V3 = if (base.x..base.x + 3).contains(&j) {
            let mut unit = [zero; 3];
            unit[j - base.x] = one;
            unit
        } else if (base.w..base.w + 4).contains(&j) {
            let m = j - base.w;
            let own: V3 = [0, 1, 2].map(|l| g.mul2(turning.k, turning.big_g[l][m]));
            let own = turn(g, own);
            let own = spatial::hold3(g, own);
            spatial::cross(g, own, world_r)
        } else {
            let own: V3 = [0, 1, 2].map(|l| a[l][j]);
            if own.iter().all(|&e| g.is_zero(e)) {
                continue;
            }
            turn(g, own)
        };
        for (row, &e) in model_a.iter_mut().zip(&column) {
            row[j] = e;
        }
    }
    model_a
}
