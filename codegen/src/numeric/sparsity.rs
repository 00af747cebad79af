//! Compile-time sparsity of the symmetric systems the generated code
//! factors by `P X Pᵀ = L D Lᵀ` (`S = A M⁻¹ Aᵀ`, and a configuration-
//! dependent `M`): an elimination order that keeps fill and sequential depth
//! low, the pattern of the unit lower factor, and which entries of a
//! solution can be nonzero.

/// The pattern of a symmetric matrix and of its `LDLᵀ` factor.
#[derive(Clone, Debug)]
pub struct Structure {
    /// `nonzero[i][j]`: entry (i, j) is not structurally zero (symmetric,
    /// diagonal included).
    pub nonzero: Vec<Vec<bool>>,
    /// Position `p` of the factorization is row `order[p]`.
    pub order: Vec<usize>,
    /// `fill[p][q]` (p > q, positions): entry (p, q) of the unit lower
    /// factor is not structurally zero.
    pub fill: Vec<Vec<bool>>,
}

impl Structure {
    /// The order and factor pattern for a matrix with these nonzeros.
    pub fn new(nonzero: Vec<Vec<bool>>) -> Self {
        let k = nonzero.len();
        let pattern: Vec<Vec<bool>> = (0..k)
            .map(|i| (0..k).map(|j| i != j && nonzero[i][j]).collect())
            .collect();
        let order = elimination_order(&pattern);
        let permuted: Vec<Vec<bool>> = (0..k)
            .map(|p| (0..k).map(|q| pattern[order[p]][order[q]]).collect())
            .collect();
        let fill = factor_pattern(&permuted);
        Structure {
            nonzero,
            order,
            fill,
        }
    }

    /// The factor pattern for a matrix with these nonzeros eliminated in
    /// the given `order` (position `p` is row `order[p]`), chosen by the
    /// caller (an indefinite matrix, whose pivots the order must keep away
    /// from zero).
    pub fn with_order(nonzero: Vec<Vec<bool>>, order: Vec<usize>) -> Self {
        let k = nonzero.len();
        let permuted: Vec<Vec<bool>> = (0..k)
            .map(|p| {
                (0..k)
                    .map(|q| p != q && nonzero[order[p]][order[q]])
                    .collect()
            })
            .collect();
        let fill = factor_pattern(&permuted);
        Structure {
            nonzero,
            order,
            fill,
        }
    }

    /// The size of the matrix.
    pub fn len(&self) -> usize {
        self.nonzero.len()
    }

    /// Whether the matrix is 0 × 0.
    pub fn is_empty(&self) -> bool {
        self.nonzero.is_empty()
    }

    /// The block of each row (natural order): rows coupled through a chain
    /// of structural nonzeros share one, numbered from 0 in the order of
    /// their first rows. `X` is block diagonal in them, so is `X⁻¹`: a
    /// right-hand side within one block has its solution there.
    pub fn blocks(&self) -> Vec<usize> {
        let k = self.len();
        let mut block = vec![usize::MAX; k];
        let mut next = 0;
        for start in 0..k {
            if block[start] != usize::MAX {
                continue;
            }
            block[start] = next;
            let mut stack = vec![start];
            while let Some(i) = stack.pop() {
                for (j, b) in block.iter_mut().enumerate() {
                    if *b == usize::MAX && (self.nonzero[i][j] || self.nonzero[j][i]) {
                        *b = next;
                        stack.push(j);
                    }
                }
            }
            next += 1;
        }
        block
    }

    /// Which entries of `x` in `X x = v` can be nonzero, for `v` nonzero
    /// where `rhs` says (in natural order): the reach of forward and back
    /// substitution through the factor's pattern.
    pub fn solution_pattern(&self, rhs: &[bool]) -> Vec<bool> {
        let k = self.len();
        let mut y = vec![false; k];
        for p in 0..k {
            y[p] = rhs[self.order[p]] || (0..p).any(|c| self.fill[p][c] && y[c]);
        }
        let mut x = vec![false; k];
        for p in (0..k).rev() {
            x[p] = y[p] || (p + 1..k).any(|c| self.fill[c][p] && x[c]);
        }
        let mut out = vec![false; k];
        for p in 0..k {
            out[self.order[p]] = x[p];
        }
        out
    }
}

/// The structural nonzeros of the unit lower factor of `S = L D Lᵀ` in the
/// given (already permuted) order: the off-diagonal pattern of `S` plus
/// fill-in (`Lᵢⱼ ≠ 0` when `Sᵢⱼ ≠ 0` or an earlier column couples i and j).
fn factor_pattern(pattern: &[Vec<bool>]) -> Vec<Vec<bool>> {
    let k = pattern.len();
    let mut l = vec![vec![false; k]; k];
    for j in 0..k {
        for i in j + 1..k {
            l[i][j] = pattern[i][j] || (0..j).any(|c| l[i][c] && l[j][c]);
        }
    }
    l
}

/// An elimination order for `S` chosen at compile time: greedily the
/// constraint whose elimination adds the least fill (minimum degree), ties
/// broken by the smallest dependency depth, then by index. The depth of a
/// pivot is one more than that of the deepest earlier pivot that updated it;
/// the factorization and both triangular solves are chains of dependent
/// divisions and multiplications along it, so a shallow order is a fast one.
/// On a chain's tridiagonal `S` this eliminates from both ends towards the
/// middle: no fill, and half the sequential depth of the natural order.
fn elimination_order(pattern: &[Vec<bool>]) -> Vec<usize> {
    let k = pattern.len();
    let mut adjacent: Vec<Vec<bool>> = pattern.to_vec();
    let mut eliminated = vec![false; k];
    let mut ready = vec![0usize; k];
    let mut order = Vec::with_capacity(k);
    for _ in 0..k {
        let neighbours = |v: usize, adjacent: &[Vec<bool>], eliminated: &[bool]| -> Vec<usize> {
            (0..k)
                .filter(|&w| w != v && !eliminated[w] && adjacent[v][w])
                .collect()
        };
        let fill = |v: usize| -> usize {
            let n = neighbours(v, &adjacent, &eliminated);
            n.iter()
                .enumerate()
                .map(|(i, &a)| n[i + 1..].iter().filter(|&&b| !adjacent[a][b]).count())
                .sum()
        };
        let Some(v) = (0..k)
            .filter(|&v| !eliminated[v])
            .min_by_key(|&v| (fill(v), ready[v], v))
        else {
            break;
        };
        let n = neighbours(v, &adjacent, &eliminated);
        for (i, &a) in n.iter().enumerate() {
            for &b in &n[i + 1..] {
                adjacent[a][b] = true;
                adjacent[b][a] = true;
            }
            ready[a] = ready[a].max(ready[v] + 1);
        }
        eliminated[v] = true;
        order.push(v);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(k: usize, edge: impl Fn(usize, usize) -> bool) -> Vec<Vec<bool>> {
        (0..k)
            .map(|i| (0..k).map(|j| i != j && edge(i, j)).collect())
            .collect()
    }

    fn permute(p: &[Vec<bool>], order: &[usize]) -> Vec<Vec<bool>> {
        let k = p.len();
        (0..k)
            .map(|a| (0..k).map(|b| p[order[a]][order[b]]).collect())
            .collect()
    }

    fn nonzeros(l: &[Vec<bool>]) -> usize {
        (0..l.len())
            .map(|i| (0..i).filter(|&j| l[i][j]).count())
            .sum()
    }

    #[test]
    fn chain_pattern_is_tridiagonal_without_fill() {
        let l = factor_pattern(&pattern(6, |i, j| i.abs_diff(j) == 1));
        for (i, row) in l.iter().enumerate() {
            for (j, &nonzero) in row.iter().enumerate().take(i) {
                assert_eq!(nonzero, i == j + 1, "({i}, {j})");
            }
        }
    }

    #[test]
    fn chain_is_eliminated_from_both_ends_without_fill() {
        let chain = pattern(6, |i, j| i.abs_diff(j) == 1);
        let order = elimination_order(&chain);
        assert_eq!(order, vec![0, 5, 1, 4, 2, 3]);
        assert_eq!(nonzeros(&factor_pattern(&permute(&chain, &order))), 5);
    }

    #[test]
    fn blocks_are_the_rows_coupled_through_nonzeros() {
        // Two chains, 0-2-4 and 1-3, and 5 alone: three blocks however
        // their rows interleave, each solution staying in its block.
        let edge = |i: usize, j: usize| i.abs_diff(j) == 2 && i.max(j) < 5;
        let mut nonzero = pattern(6, edge);
        for (i, row) in nonzero.iter_mut().enumerate() {
            row[i] = true;
        }
        let structure = Structure::new(nonzero);
        assert_eq!(structure.blocks(), vec![0, 1, 0, 1, 0, 2]);
        let reach = structure.solution_pattern(&[false, false, false, true, false, false]);
        assert_eq!(reach, vec![false, true, false, true, false, false]);
    }

    #[test]
    fn arrow_is_eliminated_hub_last_without_fill() {
        // Row and column 0 full: eliminating 0 first would couple everything.
        let arrow = pattern(4, |i, j| i == 0 || j == 0);
        assert_eq!(nonzeros(&factor_pattern(&arrow)), 6);
        let order = elimination_order(&arrow);
        assert_eq!(order.last(), Some(&0));
        assert_eq!(nonzeros(&factor_pattern(&permute(&arrow, &order))), 3);
    }
}
