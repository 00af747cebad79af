//! Stage 3, for a configuration-dependent `M` with constraints: whether
//! `gauss` solves the saddle-point system
//!
//! ```text
//! [ M  Aᵀ ] [ q̈ ]   [ F ]
//! [ A  0  ] [ μ ] = [ b ],      λ = −μ,
//! ```
//!
//! by one `L D Lᵀ` over its compile-time pattern, instead of the
//! range-space form (`M = L D Lᵀ`, `S = A M⁻¹ Aᵀ`, `S`'s factor). Where the
//! constraints touch a few coordinates each and share the rest (a legged
//! robot's feet: each foot's rows on its own leg's joints and on the
//! floating base), eliminating each group of rows right after the
//! coordinates only it touches leaves Schur complements on the shared
//! coordinates alone, while the range-space `S` couples every row to every
//! other through them (dense `k × k`).
//!
//! The matrix is indefinite, so the order must keep every pivot away from
//! zero: a coordinate's pivot positive, a multiplier's negative, `−dⱼ`
//! above `10⁻²` times the part its own coordinates contributed
//! (`Σ u²/d` over the coordinate pivots that updated it). The order is
//! chosen greedily (fewest neighbours first) among the pivots that pass
//! that test at every compile-time sample point, numerically (each
//! quaternion put on the unit sphere there, where the states are); where no
//! pivot passes at some step, or where the estimated operations are not
//! under three quarters of the range-space form's (the estimates count
//! the factorizations' and solves' operations from the patterns alone;
//! on small systems the range-space code saves more than they see: the
//! rolling disk's saddle point estimated at 94 operations against 102
//! counts 171 against 161 once generated), there is no saddle-point form. The
//! generated code repeats the test at run time with `10⁻³` and hands the solve to the runtime's dense one where it fails
//! (a leg stretched straight, where its rows alone no longer fix its
//! joints), so the order is a choice of speed, never of the answer.
//!
//! In the quaternions' velocity coordinates (`super::velocity`) every
//! coordinate is eliminated before any multiplier, so that the multipliers'
//! pivots are those of `−A M⁻¹ Aᵀ`, away from zero wherever the rows are
//! independent. Interleaved, a multiplier eliminated with its leg's joints
//! alone needs the leg's own rows to keep their rank, which the sample
//! points cannot promise: a humanoid's leg straightening loses it (on the
//! G1 standing with its joints within ±0.3 rad, 1 state in 20 handed to
//! the dense solve, 3 on three points of each foot), while the six
//! coordinates of the floating base keep every foot's rows independent.
//! It costs about 5 % more operations on the G1.
//!
//! The legs' independent eliminations are not interleaved (any order that
//! keeps each pivot after those whose columns reach it has the same
//! updates and fill, and interleaving would overlap their chains of
//! reciprocals): the code each leg's elimination reads stays in registers
//! only when it runs in one piece, and interleaved, the quadruped's `q̈`
//! is slower.

use crate::expr::{Graph, Id, Sym};
use crate::numeric::sparsity::Structure;

/// The margin a multiplier's pivot must keep at every sample point, against
/// its coordinates' part: ten times the generated code's test (`10⁻³`).
const MARGIN: f64 = 1e-2;

/// The saddle-point matrix's structure (rows `0..n` the coordinates, `n..`
/// the constraints; the elimination order chosen as the module says), or
/// `None` where the range-space form is kept. `mass_pattern` is `M`'s or
/// the auxiliary mass's pattern, `normal` the auxiliary mass's `A_RᵀA_R`
/// (`super::mass_inverse::Auxiliary::normal`) for a semi-definite `M`,
/// `range_cost` the range-space form's estimated operations. The sample
/// points put the quaternions whose `w` is in `quaternions` on the unit
/// sphere, where the states are (off it a body's `M` need not be
/// positive semi-definite, and no order would pass there).
pub fn structure(
    g: &Graph,
    (mass, mass_pattern): (&[Vec<Id>], &Structure),
    a: &[Vec<Id>],
    (normal, quaternions): (Option<&[Vec<Id>]>, &[usize]),
    (range_cost, last): (usize, bool),
) -> Option<Structure> {
    let (n, k) = (mass.len(), a.len());
    if k == 0 || n == 0 {
        return None;
    }
    let size = n + k;
    let mut nonzero: Vec<Vec<bool>> = (0..size)
        .map(|i| {
            (0..size)
                .map(|j| i < n && j < n && mass_pattern.nonzero[i][j])
                .collect()
        })
        .collect();
    for (r, row) in a.iter().enumerate() {
        for (j, &e) in row.iter().enumerate() {
            if !g.is_zero(e) {
                nonzero[n + r][j] = true;
                nonzero[j][n + r] = true;
            }
        }
    }
    let samples = sampled(g, mass, a, (normal, quaternions))?;
    let order = greedy_order(&nonzero, (n, last), samples)?;
    let structure = Structure::with_order(nonzero, order);
    (4 * saddle_cost(&structure) < 3 * range_cost).then_some(structure)
}

/// The saddle-point matrix at each sample point; `None` where a value is
/// not finite there (then nothing is decided from the samples).
fn sampled(
    g: &Graph,
    mass: &[Vec<Id>],
    a: &[Vec<Id>],
    (normal, quaternions): (Option<&[Vec<Id>]>, &[usize]),
) -> Option<Vec<Vec<Vec<f64>>>> {
    let (n, k) = (mass.len(), a.len());
    let mut entries: Vec<Id> = mass.iter().flatten().copied().collect();
    entries.extend(a.iter().flatten().copied());
    if let Some(normal) = normal {
        entries.extend(normal.iter().flatten().copied());
    }
    let mut out = Vec::new();
    for point in crate::numeric::rng::sample_points(0x5add_1e00) {
        let on_sphere = |s: Sym| match s {
            Sym::Coord(i) => match quaternions.iter().find(|&&w| (w..w + 4).contains(&i)) {
                Some(&w) => {
                    let norm = (w..w + 4)
                        .map(|j| point(Sym::Coord(j)).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    point(s) / norm
                }
                None => point(s),
            },
            _ => point(s),
        };
        let values = g.eval(&entries, &on_sphere);
        if !values.iter().all(|v| v.is_finite()) {
            return None;
        }
        let at = |offset: usize, i: usize, j: usize, width: usize| values[offset + i * width + j];
        let scale = normal.map(|_| {
            let trace: f64 = (0..n).map(|i| at(0, i, i, n)).sum();
            let norm: f64 = (0..n).map(|i| at(n * n + k * n, i, i, n)).sum();
            trace / norm
        });
        let entry = |i: usize, j: usize| match (i < n, j < n) {
            (true, true) => at(0, i, j, n) + scale.map_or(0.0, |s| s * at(n * n + k * n, i, j, n)),
            (false, true) => at(n * n, i - n, j, n),
            (true, false) => at(n * n, j - n, i, n),
            (false, false) => 0.0,
        };
        let x: Vec<Vec<f64>> = (0..n + k)
            .map(|i| (0..n + k).map(|j| entry(i, j)).collect())
            .collect();
        if !x.iter().flatten().all(|v| v.is_finite()) {
            return None;
        }
        out.push(x);
    }
    Some(out)
}

/// The elimination order: at each step, of the pivots that pass the
/// module's test at every sample, the one with the fewest remaining
/// neighbours (a coordinate before a multiplier, then the lower index);
/// with `last`, every coordinate before any multiplier; `None` where none
/// passes.
fn greedy_order(
    nonzero: &[Vec<bool>],
    (n, last): (usize, bool),
    mut samples: Vec<Vec<Vec<f64>>>,
) -> Option<Vec<usize>> {
    let size = nonzero.len();
    let mut adjacent = nonzero.to_vec();
    let mut alive = vec![true; size];
    // Per sample, each multiplier's part from coordinate pivots.
    let mut own = vec![vec![0.0_f64; size]; samples.len()];
    let mut order = Vec::with_capacity(size);
    for _ in 0..size {
        let passes = |v: usize, samples: &[Vec<Vec<f64>>], own: &[Vec<f64>]| {
            samples.iter().zip(own).all(|(x, own)| {
                let d = x[v][v];
                if v < n {
                    d > 0.0 && d.is_finite()
                } else {
                    own[v] > 0.0 && -d > MARGIN * own[v] && d.is_finite()
                }
            })
        };
        let degree = |v: usize| {
            (0..size)
                .filter(|&w| w != v && alive[w] && adjacent[v][w])
                .count()
        };
        let coordinates_left = last && alive[..n].iter().any(|&a| a);
        let pivot = (0..size)
            .filter(|&v| alive[v] && passes(v, &samples, &own))
            .filter(|&v| v < n || !coordinates_left)
            .min_by_key(|&v| (degree(v), v >= n, v))?;
        let neighbours: Vec<usize> = (0..size)
            .filter(|&w| w != pivot && alive[w] && adjacent[pivot][w])
            .collect();
        for (x, own) in samples.iter_mut().zip(&mut own) {
            let d = x[pivot][pivot];
            for &i in &neighbours {
                let scaled = x[i][pivot] / d;
                for &j in &neighbours {
                    x[i][j] -= scaled * x[pivot][j];
                }
                if pivot < n && i >= n {
                    own[i] += scaled * x[pivot][i];
                }
            }
        }
        for &i in &neighbours {
            for &j in &neighbours {
                adjacent[i][j] = true;
            }
        }
        alive[pivot] = false;
        order.push(pivot);
    }
    Some(order)
}

/// Operations of one `L D Lᵀ` over `s` (a reciprocal, the scaled column
/// and the Schur updates per pivot).
pub fn factor_cost(s: &Structure) -> usize {
    (0..s.len())
        .map(|p| {
            let m = (p + 1..s.len()).filter(|&i| s.fill[i][p]).count();
            1 + m + m * (m + 1)
        })
        .sum()
}

/// Entries of `s`'s unit lower factor.
pub fn factor_entries(s: &Structure) -> usize {
    s.fill.iter().flatten().filter(|&&f| f).count()
}

/// The saddle-point form's estimated operations: the factorization, and
/// one solve (forward, diagonal, back).
fn saddle_cost(s: &Structure) -> usize {
    factor_cost(s) + 4 * factor_entries(s) + s.len()
}

/// Operations of the forward substitution `L y = v` for `v` nonzero where
/// `rhs` says (natural order), and the pattern of `y` (by position).
fn forward_cost(s: &Structure, rhs: &[bool]) -> (usize, Vec<bool>) {
    let mut y = vec![false; s.len()];
    let mut cost = 0;
    for p in 0..s.len() {
        let terms = (0..p).filter(|&c| s.fill[p][c] && y[c]).count();
        y[p] = rhs[s.order[p]] || terms > 0;
        cost += 2 * terms;
    }
    (cost, y)
}

/// The range-space form's estimated operations, as `gauss` computes it
/// (`crate::emit::mass_inverse::factored`): `M`'s factorization,
/// `Y = L⁻¹ Aᵀ` and `z = L⁻¹ F`, `S = Yᵀ D⁻¹ Y`, `r = b − Yᵀ D⁻¹ z`, `S`'s
/// factorization and solve, and the back substitution
/// `q̈ = L⁻ᵀ D⁻¹ (z + Y λ)`.
pub fn range_cost(mass: &Structure, gram: &Structure, a: &[Vec<bool>]) -> usize {
    let (n, k) = (mass.len(), a.len());
    let mut cost = factor_cost(mass) + factor_cost(gram) + 4 * factor_entries(gram) + k;
    let columns: Vec<Vec<bool>> = a
        .iter()
        .map(|row| {
            let (c, y) = forward_cost(mass, row);
            cost += c;
            y
        })
        .collect();
    for i in 0..k {
        for j in 0..=i {
            if gram.nonzero[i][j] {
                cost += 2 * (0..n).filter(|&p| columns[i][p] && columns[j][p]).count();
            }
        }
    }
    let (z, _) = forward_cost(mass, &vec![true; n]);
    let scaled: usize = columns.iter().flatten().filter(|&&y| y).count();
    // `r`'s products `Yᵀ D⁻¹ z`, and the back substitution: `Y λ`, `L⁻ᵀ`
    // and `D⁻¹`.
    let (residual, back) = (2 * n * k, 2 * n * k + 2 * factor_entries(mass) + n);
    cost + z + scaled + residual + back
}
