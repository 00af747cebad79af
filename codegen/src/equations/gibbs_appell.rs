//! The explicit Gibbs–Appell system symbolically, for rank `r = 1`: every
//! entry of the rows of eq. 13 / 35 as an expression, for the derivation
//! (Appell's particle with `e = {x}` gives the paper's eq. 33). The code
//! that runs is `constrained::gibbs_appell`, which re-pivots at run time;
//! tests check that both agree.

use crate::equations::partition::Partition;
use crate::equations::Equations;
use crate::expr::num::Num;
use crate::expr::{Graph, Id};

/// The rows below the first of the Gibbs–Appell system, for `r = 1`.
pub struct RankOne {
    /// A copy of the system's graph with the new expressions.
    pub graph: Graph,
    /// Rows 2..n: `n` entries in coordinate order (zero at the eliminated
    /// coordinate) and the right-hand side.
    pub rows: Vec<(Vec<Id>, Id)>,
}

/// The rows of eq. 13 (diagonal `M`) or eq. 35 for the preferred partition,
/// when the rank is 1 and there are at least two coordinates.
pub fn rank_one(eq: &Equations, partition: &Partition) -> Option<RankOne> {
    let n = eq.system.dof();
    if partition.rank != 1 || n < 2 {
        return None;
    }
    let coupled = !eq.mass_inverse.is_diagonal();
    let mut g = eq.system.graph.clone();
    let e = partition.eliminated[0];
    let independent: Vec<usize> = (0..n).filter(|&j| j != e).collect();
    let k = eq.a.len();
    let a_e: Vec<Id> = (0..k).map(|i| eq.a[i][e]).collect();
    // A_e⁺ v = Σᵢ A_ie vᵢ / Σᵢ A_ie².
    let squares: Vec<Id> = a_e.iter().map(|&x| g.pown(x, Num::int(2))).collect();
    let norm = g.add(&squares);
    let inv_norm = g.pown(norm, Num::MINUS_ONE);
    let apply_pinv = |g: &mut Graph, v: &[Id]| -> Id {
        let terms: Vec<Id> = a_e.iter().zip(v).map(|(&x, &y)| g.mul2(x, y)).collect();
        let sum = g.add(&terms);
        g.mul2(sum, inv_norm)
    };
    let r: Vec<Id> = independent
        .iter()
        .map(|&j| {
            let column: Vec<Id> = (0..k).map(|i| eq.a[i][j]).collect();
            apply_pinv(&mut g, &column)
        })
        .collect();
    let y = apply_pinv(&mut g, &eq.b);
    let m = &eq.system.mass;
    let f = &eq.system.forces;
    let m_ee = m[e][e];
    let mut rows = Vec::with_capacity(independent.len());
    for (a, &ja) in independent.iter().enumerate() {
        let mut row = vec![g.int(0); n];
        for (b, &jb) in independent.iter().enumerate() {
            // B = M_II + Rᵀ M_ee R − M_Ie R − Rᵀ M_Ieᵀ
            let rmr = g.mul(&[r[a], m_ee, r[b]]);
            let mut entry = g.add2(m[ja][jb], rmr);
            if coupled {
                let c1 = g.mul2(m[ja][e], r[b]);
                let c2 = g.mul2(r[a], m[jb][e]);
                let c = g.add2(c1, c2);
                entry = g.sub(entry, c);
            }
            row[jb] = entry;
        }
        // F_I − Rᵀ F_e + (Rᵀ M_ee − M_Ie) A_e⁺ b
        let rfe = g.mul2(r[a], f[e]);
        let mut coefficient = g.mul2(r[a], m_ee);
        if coupled {
            coefficient = g.sub(coefficient, m[ja][e]);
        }
        let extra = g.mul2(coefficient, y);
        let reduced = g.sub(f[ja], rfe);
        rows.push((row, g.add2(reduced, extra)));
    }
    Some(RankOne { graph: g, rows })
}
