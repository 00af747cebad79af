//! Stage 3b: the symbolic pieces of Gauss's principle (MATH.md,
//! "Generalized-inverse forms"): `M q̈ = F + Aᵀ λ` with `S λ = r`,
//! `S = A M⁻¹ Aᵀ`, `r = b − A a`, `a = M⁻¹ F`.
//!
//! When `M` is diagonal its inverse is known symbolically, so `a`, `S`, `r`
//! and `W = M⁻¹ Aᵀ` are built as expressions: constant masses fold into them
//! and the structural zeros of `A` make structural zeros of `S`, which the
//! factorization pattern computed here skips. Otherwise `M` is factorized
//! at run time (Cholesky) and only `A`, `b`, `M`, `F` are emitted.

use crate::expr::{Graph, Id, Sym};
use crate::num::Num;

/// How `M⁻¹` is applied.
pub enum MassInverse {
    /// `M = diag(mᵢ)`: `M⁻¹ = diag(1/mᵢ)` symbolically.
    Diagonal(Diagonal),
    /// A full (possibly configuration-dependent) `M`: Cholesky at run time.
    Cholesky,
}

/// The symbolic Gauss pieces for a diagonal mass matrix.
pub struct Diagonal {
    /// The diagonal `mᵢ`, to check positivity at run time when not constant.
    pub masses: Vec<Id>,
    /// Whether every `mᵢ` is a positive number (then `acceleration` cannot fail).
    pub known_positive: bool,
    /// `a = M⁻¹ F`.
    pub unconstrained: Vec<Id>,
    /// `S = A M⁻¹ Aᵀ`, k × k, symmetric (entry (j, i) is the node of (i, j)).
    pub gram: Vec<Vec<Id>>,
    /// `r = b − A a`.
    pub residual: Vec<Id>,
    /// `q̈ = a + M⁻¹ Aᵀ λ`, in terms of the multipliers `Sym::Multiplier`.
    pub acceleration: Vec<Id>,
    /// `Fᶜ = Aᵀ λ`, in terms of the multipliers.
    pub force: Vec<Id>,
    /// `fill[i][j]` (i > j): entry (i, j) of the unit lower factor of
    /// `S = L D Lᵀ` (natural order) is not structurally zero.
    pub fill: Vec<Vec<bool>>,
}

/// Builds the Gauss pieces for `mass`, `forces`, `a`, `b`.
pub fn gauss(
    g: &mut Graph,
    mass: &[Vec<Id>],
    forces: &[Id],
    a: &[Vec<Id>],
    b: &[Id],
) -> MassInverse {
    let n = mass.len();
    let diagonal = (0..n).all(|i| (0..n).all(|j| i == j || g.is_zero(mass[i][j])));
    if !diagonal {
        return MassInverse::Cholesky;
    }
    let masses: Vec<Id> = (0..n).map(|i| mass[i][i]).collect();
    let known_positive = masses
        .iter()
        .all(|&m| g.as_num(m).is_some_and(|v| v.to_f64() > 0.0));
    let inverse: Vec<Id> = masses.iter().map(|&m| g.pown(m, Num::MINUS_ONE)).collect();
    let unconstrained: Vec<Id> = (0..n).map(|i| g.mul2(inverse[i], forces[i])).collect();
    let k = a.len();
    let weighted: Vec<Vec<Id>> = (0..n)
        .map(|i| (0..k).map(|j| g.mul2(inverse[i], a[j][i])).collect())
        .collect();
    let zero = g.int(0);
    let mut gram = vec![vec![zero; k]; k];
    for i in 0..k {
        for j in i..k {
            let shared: Vec<usize> = (0..n)
                .filter(|&l| !g.is_zero(a[i][l]) && !g.is_zero(a[j][l]))
                .collect();
            let terms: Vec<Id> = shared
                .iter()
                .map(|&l| g.mul2(a[i][l], weighted[l][j]))
                .collect();
            let s = g.add(&terms);
            gram[i][j] = s;
            gram[j][i] = s;
        }
    }
    let residual: Vec<Id> = (0..k)
        .map(|i| {
            let aa: Vec<Id> = (0..n).map(|l| g.mul2(a[i][l], unconstrained[l])).collect();
            let aa = g.add(&aa);
            g.sub(b[i], aa)
        })
        .collect();
    let fill = factor_pattern(g, &gram);
    let lambda: Vec<Id> = (0..k).map(|j| g.sym(Sym::Multiplier(j))).collect();
    let mut acceleration = Vec::with_capacity(n);
    let mut force = Vec::with_capacity(n);
    for i in 0..n {
        let mut acc = vec![unconstrained[i]];
        let mut f = Vec::with_capacity(k);
        for j in 0..k {
            acc.push(g.mul2(weighted[i][j], lambda[j]));
            f.push(g.mul2(a[j][i], lambda[j]));
        }
        acceleration.push(g.add(&acc));
        force.push(g.add(&f));
    }
    MassInverse::Diagonal(Diagonal {
        masses,
        known_positive,
        unconstrained,
        gram,
        residual,
        acceleration,
        force,
        fill,
    })
}

/// The structural nonzeros of the unit lower factor of `S = L D Lᵀ` without
/// pivoting: the pattern of `S` plus fill-in (`Lᵢⱼ ≠ 0` when `Sᵢⱼ ≠ 0` or some
/// earlier column couples rows i and j).
fn factor_pattern(g: &Graph, s: &[Vec<Id>]) -> Vec<Vec<bool>> {
    let k = s.len();
    let mut l = vec![vec![false; k]; k];
    for j in 0..k {
        for i in j + 1..k {
            l[i][j] = !g.is_zero(s[i][j]) || (0..j).any(|c| l[i][c] && l[j][c]);
        }
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_pattern_is_tridiagonal_without_fill() {
        let mut g = Graph::new();
        let one = g.int(1);
        let zero = g.int(0);
        let k: usize = 6;
        let s: Vec<Vec<Id>> = (0..k)
            .map(|i| {
                (0..k)
                    .map(|j| if i.abs_diff(j) <= 1 { one } else { zero })
                    .collect()
            })
            .collect();
        let l = factor_pattern(&g, &s);
        for i in 0..k {
            for j in 0..i {
                assert_eq!(l[i][j], i == j + 1, "({i}, {j})");
            }
        }
    }

    #[test]
    fn arrow_pattern_fills_in() {
        // First row and column full: eliminating column 0 couples everything.
        let mut g = Graph::new();
        let one = g.int(1);
        let zero = g.int(0);
        let s: Vec<Vec<Id>> = (0..4)
            .map(|i| {
                (0..4)
                    .map(|j| {
                        if i == 0 || j == 0 || i == j {
                            one
                        } else {
                            zero
                        }
                    })
                    .collect()
            })
            .collect();
        let l = factor_pattern(&g, &s);
        assert!(l[3][1] && l[3][2] && l[2][1]);
    }
}
