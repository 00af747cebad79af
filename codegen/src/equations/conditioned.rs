//! Stage 3, after the partition (`super::derive`): for a redundant set,
//! which of `S`'s rows sit where in its elimination order.
//!
//! The rank rule keeps the first rows of the order that are independent of
//! those before them and drops the rest. Any maximal independent subset
//! gives the same `q̈` in exact arithmetic, but not in rounding: a kept row
//! nearly dependent on those before it (`sin²θ` small but above the rule's
//! cutoff) makes the kept system ill-conditioned, and the rows dropped hold
//! only to rounding grown by `1/sin²θ`. Three points of a standing foot in
//! world axes, in the order x, y, z of each point, keep the second point's
//! `y` row, nearly along the first point's, and drop its `z` row, the well
//! conditioned one: on the G1, `q̈` 8e-11 from the exact one.
//!
//! So among rows of `S` with the same pattern (which any order may swap
//! without changing the factor's pattern, so the generated code's cost is
//! the same), each position takes the row that is the most independent of
//! the rows placed before it, at the model's reference configuration: every
//! coordinate zero, every quaternion the identity — where a robot read from
//! its URDF stands as its file draws it. The rows' directions are those of
//! `A`'s rows normalised to unit length (the dependencies are `M`'s too;
//! the angles are measured in the plain metric). This is a choice of speed
//! and accuracy made once at compile time, never of the answer: the rank
//! decision is still made, and checked, at run time.

use super::mass_inverse::MassInverse;
use super::Equations;
use crate::numeric::linalg::dot;
use crate::numeric::sparsity::Structure;

/// The rank rule's cutoff on `sin²θ` (`constrained::inverse::rank_tolerance`
/// in `f64`), for placing rows as the run time will drop them.
const DEPENDENT: f64 = 1e-6;

/// Reorders `S`'s rows within their pattern classes (module docs); a no-op
/// unless the set is redundant (`partition.rank` below the number of rows).
pub fn reorder(eq: &mut Equations) {
    let k = eq.a.len();
    if eq.partition.rank >= k || k < 2 {
        return;
    }
    let directions = reference_rows(eq);
    let structure = match &mut eq.mass_inverse {
        MassInverse::Factored(f) | MassInverse::Auxiliary(f) => &mut f.gram,
        MassInverse::Symbolic(s) => &mut s.structure,
    };
    let order = conditioned_order(&structure.order, &structure.nonzero, &directions);
    if order != structure.order {
        *structure = Structure::with_order(structure.nonzero.clone(), order);
    }
}

/// `A`'s rows at the reference configuration, each of unit length (a zero
/// row stays zero).
fn reference_rows(eq: &Equations) -> Vec<Vec<f64>> {
    let n = eq.system.dof();
    let mut q = vec![0.0; n];
    if let Some(bodies) = &eq.system.bodies {
        for w in super::velocity::quaternions(&bodies.tree) {
            q[w] = 1.0;
        }
    }
    let state = super::surface::StateValues {
        q,
        qd: vec![0.0; n],
        t: 0.0,
        params: vec![1.0; eq.system.parameters.len()],
    };
    super::surface::eval_a(eq, &state)
        .into_iter()
        .map(|row| {
            let norm = row.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm > 0.0 && norm.is_finite() {
                row.iter().map(|x| x / norm).collect()
            } else {
                vec![0.0; row.len()]
            }
        })
        .collect()
}

/// `order` with each position's row replaced by the row of its pattern
/// class (rows whose pattern rows in `nonzero` are equal) that has the
/// largest `sin²θ` against the rows placed before it (the Schur complement
/// of their Gram matrix, rows the rule would drop not eliminated); ties
/// keep the earlier row of `order`.
fn conditioned_order(order: &[usize], nonzero: &[Vec<bool>], rows: &[Vec<f64>]) -> Vec<usize> {
    let k = order.len();
    let mut schur: Vec<Vec<f64>> = (0..k)
        .map(|i| (0..k).map(|j| dot(&rows[i], &rows[j])).collect())
        .collect();
    let mut placed = vec![false; k];
    let mut out = Vec::with_capacity(k);
    for &at in order {
        let best = order
            .iter()
            .copied()
            .filter(|&c| !placed[c] && nonzero[c] == nonzero[at])
            .fold(None, |best: Option<usize>, c| match best {
                Some(b) if schur[c][c] <= schur[b][b] * (1.0 + 1e-9) + 1e-12 => Some(b),
                _ => Some(c),
            })
            .unwrap_or(at);
        placed[best] = true;
        out.push(best);
        let pivot = schur[best][best];
        if pivot > DEPENDENT {
            let column: Vec<f64> = (0..k).map(|i| schur[i][best]).collect();
            for (i, row) in schur.iter_mut().enumerate() {
                for (j, entry) in row.iter_mut().enumerate() {
                    *entry -= column[i] * column[j] / pivot;
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows `e · (v + ω × d)` of three points of a foot (the G1's
    /// sole points) on its velocities `(v, ω)`, the foot turned by `r`,
    /// each of unit length.
    fn foot_rows(r: [[f64; 3]; 3]) -> Vec<Vec<f64>> {
        let points = [
            [-0.05, 0.025, -0.03],
            [-0.05, -0.025, -0.03],
            [0.12, 0.03, -0.03],
        ];
        let mut rows = Vec::new();
        for p in points {
            let local: Vec<f64> = (0..3).map(|i| p[i] - points[0][i]).collect();
            let d: Vec<f64> = (0..3).map(|i| dot(&r[i], &local)).collect();
            for i in 0..3 {
                // ω · (d × eᵢ).
                let mut e = [0.0; 3];
                e[i] = 1.0;
                let cross = [
                    d[1] * e[2] - d[2] * e[1],
                    d[2] * e[0] - d[0] * e[2],
                    d[0] * e[1] - d[1] * e[0],
                ];
                let row: Vec<f64> = e.iter().chain(&cross).copied().collect();
                let norm = dot(&row, &row).sqrt();
                rows.push(row.iter().map(|x| x / norm).collect());
            }
        }
        rows
    }

    /// A rotation by `x` about x, then `y` about y, then `z` about z.
    fn turned(x: f64, y: f64, z: f64) -> [[f64; 3]; 3] {
        let (cx, sx, cy, sy, cz, sz) = (x.cos(), x.sin(), y.cos(), y.sin(), z.cos(), z.sin());
        [
            [cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
            [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
            [-sy, cy * sx, cy * cx],
        ]
    }

    /// The smallest `sin²θ` of a row the rank rule keeps, eliminating in
    /// `order`.
    fn weakest_kept(order: &[usize], rows: &[Vec<f64>]) -> f64 {
        let k = rows.len();
        let mut g: Vec<Vec<f64>> = (0..k)
            .map(|i| (0..k).map(|j| dot(&rows[i], &rows[j])).collect())
            .collect();
        let mut weakest = f64::INFINITY;
        for &p in order {
            let d = g[p][p];
            if d > DEPENDENT {
                weakest = weakest.min(d);
                let column: Vec<f64> = (0..k).map(|i| g[i][p]).collect();
                for (i, row) in g.iter_mut().enumerate() {
                    for (j, entry) in row.iter_mut().enumerate() {
                        *entry -= column[i] * column[j] / d;
                    }
                }
            }
        }
        weakest
    }

    /// The order chosen with the foot level keeps well-conditioned rows
    /// with the foot tilted and turned, where the points' own order keeps
    /// a row within a few milliradians of the others.
    #[test]
    fn the_reference_order_keeps_well_conditioned_rows_of_a_turned_foot() {
        let natural: Vec<usize> = (0..9).collect();
        let dense = vec![vec![true; 9]; 9];
        let chosen = conditioned_order(&natural, &dense, &foot_rows(turned(0.0, 0.0, 0.0)));
        let mut sorted = chosen.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, natural, "a permutation");
        for (x, y, z) in [
            (0.05, 0.03, 0.01),
            (0.02, 0.01, 0.002),
            (0.1, 0.05, 0.3),
            (0.1, 0.1, 0.6),
        ] {
            let rows = foot_rows(turned(x, y, z));
            let (before, after) = (weakest_kept(&natural, &rows), weakest_kept(&chosen, &rows));
            assert!(
                before < 1e-4,
                "the points' order keeps sin²θ {before:e} at {x}, {y}, {z}"
            );
            assert!(
                after > 1e-3,
                "the chosen order keeps sin²θ {after:e} at {x}, {y}, {z}"
            );
        }
    }

    #[test]
    fn rows_of_different_patterns_keep_their_positions() {
        let rows = vec![vec![1.0, 0.0], vec![1.0, 1e-3], vec![0.0, 1.0]];
        let nonzero = vec![
            vec![true, false, false],
            vec![false, true, true],
            vec![false, true, true],
        ];
        // Row 0 is alone in its class; rows 1 and 2 share theirs, and 2 is
        // the more independent of row 0, placed first.
        let chosen = conditioned_order(&[0, 1, 2], &nonzero, &rows);
        assert_eq!(chosen, vec![0, 2, 1]);
    }
}
