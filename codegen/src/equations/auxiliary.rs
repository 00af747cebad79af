//! For a positive semi-definite `M` (singular everywhere, e.g. a rigid
//! body in unit quaternions), the terms of Udwadia & Schutte's auxiliary
//! mass `M + s A_RᵀA_R` (`super::mass_inverse::MassInverse::Auxiliary`):
//! which rows of `A` complete `M`'s rank, and `A_RᵀA_R`.

use crate::expr::{Graph, Id};

/// The terms of Udwadia & Schutte's auxiliary mass `M + s A_RᵀA_R` that
/// are expressions; the scale `s = tr M / ‖A_R‖²_F` (the runtime's dense
/// solve answers where either underflows) and `F + s A_Rᵀ(b + db)_R`
/// (with `acceleration_corrected`'s correction `db`, so that the
/// auxiliary multipliers are the actual system's) are formed in the
/// generated code from the bound entries.
pub struct Auxiliary {
    /// The rows of `A` the auxiliary mass adds (`A_R`, in `A`'s order):
    /// the sparsest that complete `M`'s rank (below).
    pub rows: Vec<usize>,
    /// `A_RᵀA_R`, n × n, symmetric (entry (j, i) is the node of (i, j));
    /// each entry sums only the rows where both of `A`'s entries are
    /// structurally nonzero (0 where none is), and `‖A_R‖²_F = tr A_RᵀA_R`.
    pub normal: Vec<Vec<Id>>,
}

/// The rows of `A` whose squares complete `M`'s rank, sparsest first: a
/// row is taken where it raises the rank of `[M; A_R]` at every sample
/// point, until that is `n`; all rows where no subset reaches `n` there.
/// For bodies on quaternion joints this is the norms' rows alone (`M`
/// lacks just each quaternion's own direction, which its norm's gradient
/// `2q` has), so `M + s A_RᵀA_R` keeps `M`'s tree pattern and the feet's
/// rows do not enter it. Any subset gives the actual `q̈` wherever
/// `M + s A_RᵀA_R` is positive definite (`A q̈ = b` makes the added terms
/// vanish); the choice is one of speed only, since where the generated
/// factorization meets a pivot that is not positive the runtime's dense
/// solve, with all rows, answers instead.
fn auxiliary_rows(g: &Graph, mass: &[Vec<Id>], a: &[Vec<Id>]) -> Vec<usize> {
    let n = mass.len();
    let mut order: Vec<usize> = (0..a.len()).collect();
    order.sort_by_key(|&r| a[r].iter().filter(|&&e| !g.is_zero(e)).count());
    let mut entries: Vec<Id> = mass.iter().flatten().copied().collect();
    entries.extend(a.iter().flatten().copied());
    let points: Vec<Vec<Vec<f64>>> = crate::numeric::rng::sample_points(0x5e11_d3f1)
        .map(|point| {
            let values = g.eval(&entries, &point);
            values.chunks(n.max(1)).map(<[f64]>::to_vec).collect()
        })
        .collect();
    let finite = points.iter().flatten().flatten().all(|v| v.is_finite());
    let rank = |rows: &[usize], point: &[Vec<f64>]| {
        let mut stacked: Vec<Vec<f64>> = point[..n].to_vec();
        stacked.extend(rows.iter().map(|&r| point[n + r].clone()));
        crate::numeric::linalg::independent_columns(&stacked, 1e-12).len()
    };
    let all: Vec<usize> = (0..a.len()).collect();
    if !finite || n == 0 {
        return all;
    }
    let mut chosen: Vec<usize> = Vec::new();
    for r in order {
        if points.iter().all(|p| rank(&chosen, p) == n) {
            break;
        }
        let mut with = chosen.clone();
        with.push(r);
        if points.iter().all(|p| rank(&with, p) > rank(&chosen, p)) {
            chosen = with;
        }
    }
    if points.iter().all(|p| rank(&chosen, p) == n) {
        chosen.sort_unstable();
        chosen
    } else {
        all
    }
}

impl Auxiliary {
    /// The auxiliary terms of a semi-definite `M` under the rows `a`.
    pub(super) fn new(g: &mut Graph, mass: &[Vec<Id>], a: &[Vec<Id>], n: usize) -> Self {
        let rows = auxiliary_rows(g, mass, a);
        let zero = g.int(0);
        let mut normal = vec![vec![zero; n]; n];
        for i in 0..n {
            for j in 0..=i {
                let pairs: Vec<(Id, Id)> = rows
                    .iter()
                    .map(|&r| &a[r])
                    .filter(|row| !g.is_zero(row[i]) && !g.is_zero(row[j]))
                    .map(|row| (row[i], row[j]))
                    .collect();
                let terms: Vec<Id> = pairs.into_iter().map(|(x, y)| g.mul2(x, y)).collect();
                let e = g.add(&terms);
                normal[i][j] = e;
                normal[j][i] = e;
            }
        }
        Auxiliary { rows, normal }
    }
}

/// Whether `M` is numerically singular at a few pseudo-random points (all
/// of them; a point where it cannot be evaluated counts as regular).
pub(super) fn singular_everywhere(g: &Graph, mass: &[Vec<Id>]) -> bool {
    let n = mass.len();
    let entries: Vec<Id> = mass.iter().flatten().copied().collect();
    crate::numeric::rng::sample_points(0x5e11_d3f1).all(|point| {
        let values = g.eval(&entries, &point);
        if values.iter().any(|v| !v.is_finite()) {
            return false;
        }
        // n = 0 (no coordinate, refused by the checks): nothing is singular.
        let m: Vec<Vec<f64>> = values.chunks(n.max(1)).map(<[f64]>::to_vec).collect();
        crate::numeric::linalg::independent_columns(&m, 1e-12).len() < n
    })
}
