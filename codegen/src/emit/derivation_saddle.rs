//! The derivation's account of `gauss` where it solves the saddle-point
//! system (`crate::equations::saddle_point`), or that system in the
//! quaternions' velocity coordinates (`crate::equations::velocity`),
//! rather than the range-space form the generalized-inverse equation
//! describes: what `acceleration` computes, in its compile-time order.
//! Also the elimination orders every part of the derivation prints.

use crate::equations::held::HeldRows;
use crate::equations::legs::Legs;
use crate::equations::mass_inverse::Factored;
use crate::equations::strategy::Strategy;
use crate::equations::velocity::Velocity;
use crate::numeric::sparsity::Structure;
use std::fmt::Write;

/// The elimination order of a structure, each row named by `name`.
pub(super) fn order(structure: &Structure, name: impl Fn(usize) -> String) -> String {
    structure
        .order
        .iter()
        .map(|&i| name(i))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The lines for `f`'s saddle-point solve, where the strategy is one of
/// them; nothing otherwise.
pub(super) fn text(w: &mut String, f: &Factored, coordinates: &[String], strategy: Strategy) {
    let pivots = "a coordinate's pivot must be positive and a row's negative, \
                  away from 0, else the runtime's dense solve answers";
    if let (Strategy::Legs, Some(v), Some(legs)) = (strategy, &f.velocity, &f.legs) {
        velocity_text(w, v, coordinates, pivots);
        legs_text(w, v, legs, coordinates);
        return;
    }
    if let (Strategy::VelocitySaddle, Some(v)) = (strategy, &f.velocity) {
        velocity_text(w, v, coordinates, pivots);
        return;
    }
    if let (Strategy::Saddle, Some(s)) = (strategy, &f.saddle) {
        let n = f.mass.len();
        let name = |i: usize| {
            if i < n {
                coordinates[i].clone()
            } else {
                format!("μ{}", i - n)
            }
        };
        let _ = writeln!(
            w,
            "  acceleration solves instead [M Aᵀ; A 0] [q̈; μ] = [F; b], λ = −μ, by L D Lᵀ in the order\n  \
             {} ({pivots})",
            order(s, name),
        );
    }
}

/// The lines for the saddle-point solve in the quaternions' velocity
/// coordinates: the substitution `q̈_q = ½ (q α + Gᵀ β)`, the norms' rows
/// solved first, then the factorization's order of the rest.
fn velocity_text(w: &mut String, v: &Velocity, coordinates: &[String], pivots: &str) {
    let nr = v.coordinates.len();
    let name = |i: usize| {
        if i < nr {
            let c = v.coordinates[i];
            match v
                .system
                .quaternions
                .iter()
                .find(|&&(w, _)| c > w && c <= w + 3)
            {
                Some(&(w, _)) => format!("β{}", c - w - 1),
                None => coordinates[c].clone(),
            }
        } else {
            format!("μ{}", v.rows[i - nr])
        }
    };
    let quaternions: Vec<String> = v
        .system
        .quaternions
        .iter()
        .map(|&(w, r)| format!("{} (row {r})", coordinates[w]))
        .collect();
    let _ = writeln!(
        w,
        "  acceleration solves instead, in the quaternions' velocity coordinates\n  \
         q̈_q = ½ (q α + Gᵀ β), G = [−v, w I − ṽ] (T = ½ [q, Gᵀ], invertible wherever q ≠ 0),\n  \
         [TᵀMT TᵀAᵀ; A T 0] [z; μ] = [TᵀF; b], λ = −μ: each norm's row reads |q|² α = b\n  \
         on α alone, so α = b_norm / |q|² first (quaternions at {}),\n  \
         b ← b − (A T)_α α for the other rows, then L D Lᵀ of the rest ({} coordinates, {} rows) in the order\n  \
         {} ({pivots}),\n  \
         then q̈ = T z and μ_norm = ((TᵀF)_α − Σ (A T)_rα μ_r) / |q|²",
        quaternions.join(", "),
        nr,
        v.rows.len(),
        order(&v.structure, name),
    );
    for held in &v.system.held {
        held_text(w, held);
    }
}

/// The lines for a body held at three or more points: its rows solved as
/// the body's own six (`crate::equations::held`).
fn held_text(w: &mut String, held: &HeldRows) {
    let rows: Vec<String> = held
        .triples
        .iter()
        .map(|[x, _, z]| format!("{x}–{z}"))
        .collect();
    let [a0, _, a2] = held.angular();
    let _ = writeln!(
        w,
        "  rows {} hold {} points rᵢ of one body (rank 6): solved as the body's own six,\n  \
         the first point's rows and its angular acceleration J_ω q̈ = −J̇_ω q̇ (world axes, in place of rows {a0}–{a2}),\n  \
         with right-hand side N Ĉ⁺ b (the points' rows in the least-squares sense of their accelerations,\n  \
         exact where they are consistent): Ĉ = diag(R) Cᴸ diag(R)ᵀ, Cᴸ = [1, −[rᵢ]×] a constant;\n  \
         the points' λ = R Cᴸ (CᴸᵀCᴸ)⁻¹ [fᴸ; r₁ × fᴸ + τᴸ] from the body's wrench, the least λ",
        rows.join(", "),
        held.triples.len(),
    );
}

/// The lines for the legs' elimination, which replaces the factorization
/// of the saddle-point system's rest: each leg's joints and its foot's rows
/// by name, the base's six unknowns, and the closed form
/// (`emit/mass_inverse/factored/legs.rs`).
fn legs_text(w: &mut String, v: &Velocity, legs: &Legs, coordinates: &[String]) {
    let joint = |p: usize| match v.coordinates.get(p) {
        Some(&c) => coordinates.get(c).cloned().unwrap_or_default(),
        None => String::new(),
    };
    let row = |r: usize| v.rows.get(r).map_or_else(String::new, |r| format!("μ{r}"));
    let each: Vec<String> = legs
        .legs
        .iter()
        .map(|(joints, rows)| {
            format!(
                "({}; {})",
                joints.map(joint).join(", "),
                rows.map(row).join(", ")
            )
        })
        .collect();
    let _ = writeln!(
        w,
        "  in place of that factorization, a floating base on {} legs, each (joints; foot's rows):\n  \
         {}\n  \
         eliminated through its foot's rows E u + J θ̈ = b in closed form (u = (z, β), the base's {}):\n  \
         θ̈ = c − N u, c = J⁻¹ b, N = J⁻¹ E; S u = r, S = M_bb − Σ (M_lbᵀ N + Nᵀ M_lb − Nᵀ M_ll N),\n  \
         r = f_b − Σ (M_lbᵀ c + Nᵀ (f_l − M_ll c)); μ = J⁻ᵀ (f_l − M_lb u − M_ll θ̈)\n  \
         (a leg with |det J| below 10⁻³ times its rows' lengths, or a pivot of S that is not positive,\n  \
         hands the solve to the runtime's dense one)",
        legs.legs.len(),
        each.join(", "),
        legs.base.map(joint).join(", "),
    );
}
