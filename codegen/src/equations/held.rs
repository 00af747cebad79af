//! Stage 3, in the velocity form ([`super::velocity`]): a body held at
//! `k ≥ 3` of its points under a free base (`position(body, rᵢ) == cᵢ`,
//! each `rᵢ` numbers in the body's frame) has `3k` rows of rank 6, and
//! the saddle-point solve needs independent rows. They are replaced by the
//! body's own six, exactly, with no rank decided at run time.
//!
//! Each point's acceleration is `p̈ᵢ = ö + ω̇ × Δᵢ + ω × (ω × Δᵢ)`, with
//! `Δᵢ = R rᵢ` (`o` the body's origin, `R` its attitude), so the points'
//! rows are `A_g = Ĉ J` and `b_g = Ĉ β + c`, where `J` gives the body's
//! `[ö; ω̇]` from the unknowns, `β` its rate at `q̈ = 0` with the sign of
//! `b`, `Ĉ = D₉ Cᴸ D₆ᵀ` (`D` block diagonals of `R`; `Cᴸ`, `3k × 6`, the
//! rows `[1, −[rᵢ]×]`, numbers) and `cᵢ = −ω × (ω × Δᵢ)`, the part of each
//! point's rate that no motion of the body makes. The points fix the body
//! when `Cᴸ` has rank 6 (three points not on one line), decided exactly at
//! compile time from `CᴸᵀCᴸ`, a constant.
//!
//! The six rows solved are the first point's three (in the base's axes,
//! as [`super::in_base`] writes them) and the body's angular acceleration
//! (`J_ω q̈`, world axes): `N J` for an invertible `N`. Their right-hand
//! side is `N Ĉ⁺ b_g`, `Ĉ⁺ = (ĈᵀĈ)⁻¹ Ĉᵀ = D₆ G D₉ᵀ` with `G = (CᴸᵀCᴸ)⁻¹ Cᴸᵀ`
//! a constant: the points' rows hold in the least-squares sense of their
//! accelerations, exactly where they are consistent (on the constraint
//! surface, where every choice of six independent rows gives the same
//! `q̈`). With `cᴸᵢ = |ωᴸ|² rᵢ − ωᴸ (ωᴸ · rᵢ)` in the body's axes
//! (`ωᴸ = Rᵀ ω`), that right-hand side is the first point's `b` plus
//! `R_B ((P G − E₁) cᴸ)` (`R_B = R̂ᵀ R`, the body in the base's axes;
//! `P = [1, −[r₁]×]`; `E₁` picks the first point), and `−J̇_ω q̇` plus
//! `R (G_ω cᴸ)` (`G_ω` the last three rows of `G`).
//!
//! The multipliers: with `μ` the six rows' (`μ₁` in the base's axes, `μ_ω`
//! in the world's), the body's wrench in its own axes is
//! `[fᴸ; r₁ × fᴸ + τᴸ]`, `fᴸ = R_Bᵀ μ₁`, `τᴸ = Rᵀ μ_ω`, and the least `λ`
//! of the points' rows that exerts it is `λᵢ = R (Cᴸ (CᴸᵀCᴸ)⁻¹ [..])ᵢ` in
//! world axes: `Aᵀλ` is the six rows' force, and `λ` lies in the range of
//! `Ĉ`, which is the minimum-norm multiplier of the points' rows.

use super::in_base::InBaseRows;
use crate::bodies::spatial::{self, M3, V3};
use crate::expr::num::Num;
use crate::expr::{Graph, Id};
use crate::model::HeldBody;

/// The largest condition number, in the max norm, of `CᴸᵀCᴸ` whose points
/// are taken to fix their body: beyond it the points are nearly on one
/// line, and their rows keep the general solve's rank decision.
const CONDITION: f64 = 1e8;

/// A body held at `k ≥ 3` points, its `3k` rows solved as six.
#[derive(Clone, Debug)]
pub struct HeldRows {
    /// The points' model rows (`x`, `y`, `z` of each), in order; the first
    /// point's are solved as written (in the base's axes), the second's
    /// carry the body's angular rows, the rest are not solved.
    pub triples: Vec<[usize; 3]>,
    /// The six rows' right-hand side: the first point's three in the
    /// base's axes, the angular three in the world's.
    pub b: [Id; 6],
    /// The body's angular rows `J_ω` over `q̇` (world axes), which the
    /// velocity form turns by `T` into the second point's rows of `A T`.
    pub angular_rows: [Vec<Id>; 3],
    /// `R`, the body's attitude (body axes → world).
    pub rotation: M3,
    /// `R_B = R̂ᵀ R`, the body's axes in the base's.
    pub relative: M3,
    /// `[P G; G_ω]`, 6 × 3k: the six right-hand sides' change from a
    /// change `δᴸ` of the points' (in the body's axes).
    pub correction: Vec<[Num; 6]>,
    /// `Cᴸ (CᴸᵀCᴸ)⁻¹ [1 0; [r₁]× 1]`, 3k × 6: the points' multipliers in
    /// the body's axes from `[fᴸ; τᴸ]`.
    pub multipliers: Vec<[Num; 6]>,
}

impl HeldRows {
    /// The rows the solve leaves out: every point's after the second.
    pub fn dropped(&self) -> impl Iterator<Item = usize> + '_ {
        self.triples.iter().skip(2).flatten().copied()
    }

    /// The rows carrying the body's angular acceleration.
    pub fn angular(&self) -> [usize; 3] {
        self.triples[1]
    }

    /// The six rows solved, in the order of `b`: the first point's, then
    /// the angular ones.
    pub fn six(&self) -> [usize; 6] {
        let ([a, b, c], [d, e, f]) = (self.triples[0], self.triples[1]);
        [a, b, c, d, e, f]
    }
}

/// `G = (CᴸᵀCᴸ)⁻¹ Cᴸᵀ` (6 × 3k) by columns, one per point row, for a set
/// of points `rᵢ` that fix their body; `None` otherwise. Its transpose is
/// `Cᴸ (CᴸᵀCᴸ)⁻¹` (the inverse is symmetric).
fn constants(points: &[[Num; 3]]) -> Option<Vec<[Num; 6]>> {
    let (z, o) = (Num::ZERO, Num::ONE);
    // The rows [1, −[r]×] of each point.
    let rows: Vec<[Num; 6]> = points
        .iter()
        .flat_map(|&[x, y, w]| {
            [
                [o, z, z, z, w, -y],
                [z, o, z, -w, z, x],
                [z, z, o, y, -x, z],
            ]
        })
        .collect();
    let gram: Vec<Vec<Num>> = (0..6)
        .map(|i| {
            (0..6)
                .map(|j| rows.iter().fold(z, |s, r| s + r[i] * r[j]))
                .collect()
        })
        .collect();
    let inverse = crate::numeric::linalg::exact_inverse(&gram)?;
    let norm = |m: &[Vec<Num>]| {
        m.iter()
            .flatten()
            .fold(0.0f64, |s, x| s.max(x.to_f64().abs()))
    };
    // A NaN condition (a float literal's overflow) fails it too.
    let condition = 6.0 * norm(&gram) * norm(&inverse);
    if condition.is_nan() || condition > CONDITION {
        return None;
    }
    Some(
        rows.iter()
            .map(|r| [0, 1, 2, 3, 4, 5].map(|i| (0..6).fold(z, |s, j| s + inverse[i][j] * r[j])))
            .collect(),
    )
}

/// `[1, −[r]×] x` for the first three and last three entries of `x`.
fn at_point(r: [Num; 3], x: [Num; 6]) -> [Num; 3] {
    let [rx, ry, rz] = r;
    let [f0, f1, f2, t0, t1, t2] = x;
    // f − r × t.
    [
        f0 + -(ry * t2 + -(rz * t1)),
        f1 + -(rz * t0 + -(rx * t2)),
        f2 + -(rx * t1 + -(ry * t0)),
    ]
}

/// The six rows of every held body whose points under one of the velocity
/// form's free bases (`free`: each one's `x` and `R̂`) fix it.
pub fn reduce(
    g: &mut Graph,
    held: &[HeldBody],
    (in_base, free): (&[InBaseRows], &[(usize, M3)]),
) -> Vec<HeldRows> {
    let mut out = Vec::new();
    for body in held {
        let triples: Vec<&InBaseRows> = in_base.iter().filter(|t| t.body.0 == body.body).collect();
        let Some(first) = triples.first() else {
            continue;
        };
        let Some(&(_, base)) = free.iter().find(|&&(x, _)| x == first.base) else {
            continue;
        };
        let points: Option<Vec<[Num; 3]>> = triples
            .iter()
            .map(|t| {
                let [x, y, z] = t.body.1.map(|e| g.as_num(e));
                Some([x?, y?, z?])
            })
            .collect();
        let Some(points) = points.filter(|p| p.len() >= 3) else {
            continue;
        };
        if let Some(rows) = held_rows(g, body, (&triples, &points), base) {
            out.push(rows);
        }
    }
    out
}

/// The six rows' right-hand side and constants of one held body, or
/// `None` where its points do not fix it.
fn held_rows(
    g: &mut Graph,
    body: &HeldBody,
    (triples, points): (&[&InBaseRows], &[[Num; 3]]),
    base: M3,
) -> Option<HeldRows> {
    let gmat = constants(points)?;
    let r1 = points[0];
    // P G and G_ω, one column per point row.
    let correction: Vec<[Num; 6]> = gmat
        .iter()
        .map(|c| {
            let [p0, p1, p2] = at_point(r1, *c);
            [p0, p1, p2, c[3], c[4], c[5]]
        })
        .collect();
    let rotation = body.rotation;
    let relative = spatial::mat_mul(g, &spatial::transpose(&base), &rotation);
    let rates = unmatched_rates(g, body, points);
    let b = right_hand_side(g, (body, triples[0]), (&correction, &rates), &relative);
    Some(HeldRows {
        triples: triples.iter().map(|t| t.rows).collect(),
        b,
        angular_rows: body.angular.jacobian.clone(),
        rotation,
        relative,
        multipliers: gmat.iter().map(|row| from_wrench(r1, *row)).collect(),
        correction,
    })
}

/// `cᴸᵢ = |ωᴸ|² rᵢ − ωᴸ (ωᴸ · rᵢ)` of every point, `ωᴸ = Rᵀ ω`: the part of
/// its rate at `q̈ = 0` that no rigid motion of the body gives, in the
/// body's axes, one entry per point row.
fn unmatched_rates(g: &mut Graph, body: &HeldBody, points: &[[Num; 3]]) -> Vec<Id> {
    let omega = spatial::mat_t_vec(g, &body.rotation, body.angular.velocity);
    let omega = spatial::hold3(g, omega);
    let squared = spatial::dot(g, omega, omega);
    let mut rates: Vec<Id> = Vec::with_capacity(3 * points.len());
    for &[x, y, z] in points {
        let r = [x, y, z].map(|c| g.num(c));
        let along = spatial::dot(g, omega, r);
        let outward = spatial::scale(g, squared, r);
        let inward = spatial::scale(g, along, omega);
        rates.extend(spatial::sub(g, outward, inward));
    }
    rates
}

/// The six rows' `b`: the first point's plus `R_B ((P G − E₁) cᴸ)` (its
/// own rate is in its `b` already), then `−J̇_ω q̇ + R (G_ω cᴸ)`.
fn right_hand_side(
    g: &mut Graph,
    (body, first): (&HeldBody, &InBaseRows),
    (correction, rates): (&[[Num; 6]], &[Id]),
    relative: &M3,
) -> [Id; 6] {
    let combine = |g: &mut Graph, i: usize, skip_first: bool| {
        let items: Vec<(Id, Num)> = (correction.iter().zip(rates).enumerate())
            .map(|(c, (w, &rate))| {
                let w = if skip_first && c == i {
                    w[i] + -Num::ONE
                } else {
                    w[i]
                };
                (rate, w)
            })
            .filter(|(_, w)| !w.is_zero())
            .collect();
        g.linear_combination(items)
    };
    let at_first: V3 = [0, 1, 2].map(|i| combine(g, i, true));
    let turning: V3 = [3, 4, 5].map(|i| combine(g, i, false));
    let at_first = spatial::mat_vec(g, relative, at_first);
    let turning = spatial::mat_vec(g, &body.rotation, turning);
    let own = spatial::neg(g, body.angular.bias);
    let [x, y, z] = spatial::add(g, first.b, at_first);
    let [u, v, w] = spatial::add(g, own, turning);
    [x, y, z, u, v, w]
}

/// A row of `Cᴸ (CᴸᵀCᴸ)⁻¹ [1 0; [r₁]× 1]` from the same row of
/// `Cᴸ (CᴸᵀCᴸ)⁻¹`: `row · [f; r₁ × f + τ]`, so the force's weights gain
/// `t × r₁` (`t` the torque's weights: `t · (r₁ × f) = (t × r₁) · f`).
fn from_wrench(r1: [Num; 3], row: [Num; 6]) -> [Num; 6] {
    let [_, _, _, t0, t1, t2] = row;
    let [rx, ry, rz] = r1;
    // r₁ × t, subtracted.
    let plus = [
        ry * t2 + -(rz * t1),
        rz * t0 + -(rx * t2),
        rx * t1 + -(ry * t0),
    ];
    [
        row[0] + -plus[0],
        row[1] + -plus[1],
        row[2] + -plus[2],
        t0,
        t1,
        t2,
    ]
}
