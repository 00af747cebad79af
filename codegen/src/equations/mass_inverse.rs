//! Stage 3, called by `constraint_equations` (`super`) once `A` and `b`
//! are built: the symbolic pieces of Gauss's principle (Udwadia & Kalaba,
//! the generalized-inverse forms, eq. 24–26): `M q̈ = F + Aᵀ λ` with `S λ = r`,
//! `S = A M⁻¹ Aᵀ`, `r = b − A a`, `a = M⁻¹ F`.
//!
//! When `M⁻¹` is known symbolically — `M` diagonal (`diag(1/mᵢ)`), or `M` a
//! numeric constant (inverted exactly, in rationals, at compile time) — `a`,
//! `S`, `r` and `W = M⁻¹ Aᵀ` are built as expressions: constant masses fold
//! into them, no factorization of `M` runs, and the structural zeros of `A`
//! make structural zeros of `S`, which the factorization pattern computed
//! here skips. Otherwise (`M(q)` full) `M` is factored in generated code
//! on its compile-time pattern ([`Factored`]); a positive semi-definite `M`
//! (singular everywhere) the same way through its auxiliary mass
//! `M + s A_RᵀA_R`, whose pattern is `M`'s and `A_RᵀA_R`'s, `A_R` the
//! sparsest rows that complete `M`'s rank ([`Auxiliary`]).

use super::auxiliary::singular_everywhere;
pub use super::auxiliary::Auxiliary;
use super::velocity::Bodies;
use crate::expr::common_factors::Factorer;
use crate::expr::num::Num;
use crate::expr::{Graph, Id, Node, Sym};
use crate::numeric::linalg::exact_inverse;
use crate::numeric::sparsity::Structure;

/// How `M⁻¹` is applied.
pub enum MassInverse {
    /// `M⁻¹` as expressions: `M` diagonal, or a numeric constant.
    Symbolic(Box<Symbolic>),
    /// A configuration-dependent `M`: factored in generated code on its
    /// compile-time pattern, then `W = M⁻¹ Aᵀ` and `S = A W` on theirs.
    Factored(Box<Factored>),
    /// `M` only positive semi-definite (singular at every sampled point,
    /// e.g. a rigid body in unit quaternions): Udwadia & Schutte's
    /// auxiliary system `M + s A_RᵀA_R`, `F + s A_Rᵀb_R`, which has the
    /// same accelerations wherever it is positive definite, factored in
    /// generated code as [`MassInverse::Factored`] on the pattern of
    /// `M + A_RᵀA_R` (the `Factored`'s `auxiliary` is set).
    Auxiliary(Box<Factored>),
}

impl MassInverse {
    /// Whether `M` is diagonal, so that it never couples eliminated and
    /// independent coordinates (Gibbs–Appell eq. 18 rather than eq. 37).
    pub fn is_diagonal(&self) -> bool {
        matches!(self, MassInverse::Symbolic(s) if s.diagonal)
    }

    /// Whether the solve can fail (`acceleration` returns a `Result`):
    /// only when `M` is not known positive definite at compile time.
    pub fn fallible(&self) -> bool {
        match self {
            MassInverse::Symbolic(d) => !d.known_positive,
            MassInverse::Factored(_) | MassInverse::Auxiliary(_) => true,
        }
    }
}

/// The compile-time structure of Gauss's principle for a configuration-
/// dependent `M` (only `M`'s lower triangle is read, as by a Cholesky
/// factorization).
pub struct Factored {
    /// The pattern of `M`, its elimination order and factor pattern.
    pub mass: Structure,
    /// `weighted[i][j]`: entry (i, j) of `W = M⁻¹ Aᵀ` can be nonzero.
    pub weighted: Vec<Vec<bool>>,
    /// The pattern of `S = A W`, its order and factor pattern.
    pub gram: Structure,
    /// For a semi-definite `M`: the terms of its auxiliary mass, whose
    /// pattern `mass` then is (`M`'s and `AᵀA`'s).
    pub auxiliary: Option<Auxiliary>,
    /// The saddle-point system's structure where `gauss` solves that
    /// instead of the range-space form (`super::saddle_point`).
    pub saddle: Option<Structure>,
    /// For bodies on quaternion joints, `gauss`'s system in their velocity
    /// coordinates where that has a saddle-point form
    /// (`super::velocity`); it then replaces `saddle`.
    pub velocity: Option<super::velocity::Velocity>,
    /// For a floating base standing on legs, the legs of `velocity`'s
    /// saddle-point system, each eliminated through its foot's rows
    /// (`super::legs`); the velocity form is then solved leg by leg.
    pub legs: Option<super::legs::Legs>,
}

impl Factored {
    /// The structure for the matrix factored: `M`, or for `auxiliary` the
    /// auxiliary mass (nonzero where `M` or `AᵀA` is).
    fn new(
        g: &mut Graph,
        (mass, tree): (&[Vec<Id>], Option<Bodies>),
        a: &[Vec<Id>],
        auxiliary: Option<Auxiliary>,
    ) -> Self {
        let (n, k) = (mass.len(), a.len());
        let mass_entries = mass;
        let nonzero = |i: usize, j: usize| {
            let (i, j) = (i.max(j), i.min(j));
            !g.is_zero(mass[i][j])
                || auxiliary
                    .as_ref()
                    .is_some_and(|x| !g.is_zero(x.normal[i][j]))
        };
        let mass = Structure::new(
            (0..n)
                .map(|i| (0..n).map(|j| nonzero(i, j)).collect())
                .collect(),
        );
        let mut weighted = vec![vec![false; k]; n];
        for (j, row) in a.iter().enumerate() {
            let rhs: Vec<bool> = row.iter().map(|&e| !g.is_zero(e)).collect();
            for (i, reach) in mass.solution_pattern(&rhs).into_iter().enumerate() {
                weighted[i][j] = reach;
            }
        }
        let gram = Structure::new(
            (0..k)
                .map(|i| {
                    (0..k)
                        .map(|j| (0..n).any(|l| !g.is_zero(a[i][l]) && weighted[l][j]))
                        .collect()
                })
                .collect(),
        );
        let pattern: Vec<Vec<bool>> = a
            .iter()
            .map(|row| row.iter().map(|&e| !g.is_zero(e)).collect())
            .collect();
        let range_cost = super::saddle_point::range_cost(&mass, &gram, &pattern);
        let quaternions = tree.map_or_else(Vec::new, |t| super::velocity::quaternions(t.bodies));
        let saddle = super::saddle_point::structure(
            g,
            (mass_entries, &mass),
            a,
            (auxiliary.as_ref().map(|x| &x.normal[..]), &quaternions),
            (range_cost, false),
        );
        let velocity = tree.and_then(|t| super::velocity::form(g, t, a, range_cost));
        // A held body's rows are solved as six of their own, which the
        // legs' elimination does not read.
        let legs = (velocity.as_ref())
            .filter(|v| v.system.held.is_empty())
            .and_then(super::legs::find);
        Factored {
            mass,
            weighted,
            gram,
            auxiliary,
            saddle,
            velocity,
            legs,
        }
    }
}

/// The symbolic Gauss pieces, for a mass matrix whose inverse is known.
///
/// They are built for the constraints `Â q̈ = b̂`, `Â = D A`, `b̂ = D b`,
/// where the diagonal `D` divides each row by the numeric content of its
/// entries (`2·x1, 2·y1` becomes `x1, y1`), and with `M` divided by `μ`,
/// the common mass of a diagonal `M` whose masses are all one expression
/// (else `μ = 1`): `q̈` is the same, `S̃ = μ D S D`, `r̃ = D r`, `λ̃ = D⁻¹ λ / μ`,
/// `Fᶜ = μ Âᵀ λ̃`. The scaled system needs fewer operations (the constants
/// and the mass cancel, as a hand derivation would cancel them); a
/// correction `db` of `acceleration_corrected` and the right-hand sides of
/// the projection and of the Jacobian's tangent systems are scaled by `D`.
pub struct Symbolic {
    /// The diagonal masses `mᵢ` of a diagonal `M` (the emitted code checks
    /// at run time those that are not positive constants); empty for a
    /// constant non-diagonal `M`, whose positive definiteness the model
    /// stage checked at compile time.
    pub masses: Vec<Id>,
    /// Whether `M` is known positive definite (then `acceleration` cannot fail).
    pub known_positive: bool,
    /// Whether `M` is diagonal (else a constant with coupling terms).
    pub diagonal: bool,
    /// `M⁻¹`, n × n (structural zeros are the literal 0).
    pub inverse: Vec<Vec<Id>>,
    /// The row scaling `D` (positive rationals; 1 where a row has no
    /// numeric content).
    pub scale: Vec<Num>,
    /// The common mass `μ` that `M` was divided by, if any.
    pub common_mass: Option<Id>,
    /// `Â = D A`, k × n.
    pub rows: Vec<Vec<Id>>,
    /// `W̃ = μ M⁻¹ Âᵀ`, n × k.
    pub weighted: Vec<Vec<Id>>,
    /// `a = M⁻¹ F`.
    pub unconstrained: Vec<Id>,
    /// `S̃ = Â W̃`, k × k, symmetric (entry (j, i) is the node of (i, j)).
    pub gram: Vec<Vec<Id>>,
    /// `r̃ = b̂ − Â a`.
    pub residual: Vec<Id>,
    /// `q̈ = a + W̃ λ̃`, in terms of the multipliers `Sym::Multiplier` (λ̃).
    pub acceleration: Vec<Id>,
    /// `Fᶜ = μ Âᵀ λ̃`, in terms of the multipliers.
    pub force: Vec<Id>,
    /// The pattern of `S`, its elimination order (position `p` of
    /// `P S Pᵀ = L D Lᵀ` is constraint `order[p]`) and the pattern of `L`,
    /// chosen at compile time.
    pub structure: Structure,
}

/// Builds the Gauss pieces for `mass`, `forces`, `a`, `b`.
pub fn build(
    g: &mut Graph,
    factorer: &mut Factorer,
    (mass, tree): (&[Vec<Id>], Option<Bodies>),
    forces: &[Id],
    a: &[Vec<Id>],
    b: &[Id],
) -> MassInverse {
    let n = mass.len();
    if singular_everywhere(g, mass) {
        let auxiliary = Auxiliary::new(g, mass, a, n);
        let f = Factored::new(g, (mass, tree), a, Some(auxiliary));
        return MassInverse::Auxiliary(Box::new(f));
    }
    let zero = g.int(0);
    let diagonal = (0..n).all(|i| (0..n).all(|j| i == j || g.is_zero(mass[i][j])));
    let Some((inverse, masses, known_positive)) = symbolic_inverse(g, mass, diagonal, zero) else {
        let f = Factored::new(g, (mass, tree), a, None);
        return MassInverse::Factored(Box::new(f));
    };
    let known = (inverse, masses, known_positive, diagonal);
    MassInverse::Symbolic(Box::new(symbolic(g, factorer, known, forces, a, b)))
}

/// Gauss's pieces as expressions where `M⁻¹` is known (`known`: as
/// [`symbolic_inverse`] gives it, and whether `M` is diagonal): the rows
/// scaled (`Â = D A`, `b̂ = D b`), then `a`, `W`, `S`, `r`, `q̈` and the
/// force, with their common factors pulled out.
fn symbolic(
    g: &mut Graph,
    factorer: &mut Factorer,
    (inverse, masses, known_positive, diagonal): (Vec<Vec<Id>>, Vec<Id>, bool, bool),
    forces: &[Id],
    a: &[Vec<Id>],
    b: &[Id],
) -> Symbolic {
    let (n, zero) = (inverse.len(), g.int(0));
    let (scale, rows, b_hat) = scaled_rows(g, a, b);
    // The projection's M̃⁻¹ = μ M⁻¹ (the identity for a common mass μ).
    let common_mass = (diagonal && n > 0 && masses.iter().all(|&m| m == masses[0]))
        .then(|| masses[0])
        .filter(|&m| !g.as_num(m).is_some_and(|v| v.is_one()));
    let one = g.int(1);
    let projection_inverse: Vec<Vec<Id>> = match common_mass {
        Some(_) => (0..n)
            .map(|i| (0..n).map(|j| if i == j { one } else { zero }).collect())
            .collect(),
        None => inverse.clone(),
    };
    let unconstrained: Vec<Id> = (0..n)
        .map(|i| apply(g, &inverse, &|l| forces[l], i))
        .collect();
    let k = a.len();
    let weighted: Vec<Vec<Id>> = (0..n)
        .map(|i| {
            (0..k)
                .map(|j| apply(g, &projection_inverse, &|l| rows[j][l], i))
                .collect()
        })
        .collect();
    let (gram, residual) = gram_and_residual(g, &rows, &weighted, &unconstrained, &b_hat);
    let structure = Structure::new(
        (0..k)
            .map(|i| (0..k).map(|j| !g.is_zero(gram[i][j])).collect())
            .collect(),
    );
    let (acceleration, force) = motion(g, &rows, &weighted, &unconstrained, common_mass);
    // The pieces as the derivation prints them and the code computes
    // them: with common factors pulled out (`crate::expr::common_factors`).
    let unconstrained = factorer.factor_all(g, &unconstrained);
    let weighted = factorer.factor_rows(g, &weighted);
    let gram = factorer.factor_rows(g, &gram);
    let residual = factorer.factor_all(g, &residual);
    let acceleration = factorer.factor_all(g, &acceleration);
    let force = factorer.factor_all(g, &force);
    Symbolic {
        masses,
        known_positive,
        diagonal,
        inverse,
        scale,
        common_mass,
        rows,
        weighted,
        unconstrained,
        gram,
        residual,
        acceleration,
        force,
        structure,
    }
}

/// `Â = D A` and `b̂ = D b`, with the row scales `D` ([`row_scale`]).
fn scaled_rows(g: &mut Graph, a: &[Vec<Id>], b: &[Id]) -> (Vec<Num>, Vec<Vec<Id>>, Vec<Id>) {
    let scale: Vec<Num> = a.iter().map(|row| row_scale(g, row)).collect();
    let rows: Vec<Vec<Id>> = a
        .iter()
        .zip(&scale)
        .map(|(row, &d)| row.iter().map(|&e| scaled(g, e, d)).collect())
        .collect();
    let b_hat: Vec<Id> = b
        .iter()
        .zip(&scale)
        .map(|(&e, &d)| scaled(g, e, d))
        .collect();
    (scale, rows, b_hat)
}

/// `M⁻¹` as expressions, the diagonal masses and whether `M` is known
/// positive definite, where `M` is diagonal or a numeric constant with an
/// exact inverse; `None` otherwise (`M` is factored in generated code).
fn symbolic_inverse(
    g: &mut Graph,
    mass: &[Vec<Id>],
    diagonal: bool,
    zero: Id,
) -> Option<(Vec<Vec<Id>>, Vec<Id>, bool)> {
    let n = mass.len();
    if diagonal {
        let masses: Vec<Id> = (0..n).map(|i| mass[i][i]).collect();
        let known_positive = masses
            .iter()
            .all(|&m| g.as_num(m).is_some_and(|v| v.to_f64() > 0.0));
        let mut inverse = vec![vec![zero; n]; n];
        for (i, &m) in masses.iter().enumerate() {
            inverse[i][i] = g.pown(m, Num::MINUS_ONE);
        }
        return Some((inverse, masses, known_positive));
    }
    let constant: Option<Vec<Vec<Num>>> = mass
        .iter()
        .map(|row| row.iter().map(|&e| g.as_num(e)).collect())
        .collect();
    let inverse = exact_inverse(&constant?)?;
    let inverse = inverse
        .into_iter()
        .map(|row| row.into_iter().map(|x| g.num(x)).collect())
        .collect();
    Some((inverse, Vec::new(), true))
}

/// `d · e`, or `e` itself for `d = 1`.
fn scaled(g: &mut Graph, e: Id, d: Num) -> Id {
    if d.is_one() {
        e
    } else {
        let d = g.num(d);
        g.mul2(d, e)
    }
}

/// Row `i` of `M⁻¹ v` as an expression; structural zeros of `M⁻¹` and `v`
/// vanish.
fn apply(g: &mut Graph, inverse: &[Vec<Id>], v: &dyn Fn(usize) -> Id, i: usize) -> Id {
    let terms: Vec<Id> = (0..inverse.len())
        .map(|l| g.mul2(inverse[i][l], v(l)))
        .collect();
    g.add(&terms)
}

/// `S = Â W` (symmetric, each entry built once) and `r = b̂ − Â a`.
fn gram_and_residual(
    g: &mut Graph,
    rows: &[Vec<Id>],
    weighted: &[Vec<Id>],
    unconstrained: &[Id],
    b_hat: &[Id],
) -> (Vec<Vec<Id>>, Vec<Id>) {
    let (n, k) = (unconstrained.len(), rows.len());
    let zero = g.int(0);
    let mut gram = vec![vec![zero; k]; k];
    for i in 0..k {
        for j in i..k {
            let shared: Vec<usize> = (0..n)
                .filter(|&l| !g.is_zero(rows[i][l]) && !g.is_zero(weighted[l][j]))
                .collect();
            let terms: Vec<Id> = shared
                .iter()
                .map(|&l| g.mul2(rows[i][l], weighted[l][j]))
                .collect();
            let s = g.add(&terms);
            gram[i][j] = s;
            gram[j][i] = s;
        }
    }
    let residual: Vec<Id> = (0..k)
        .map(|i| {
            let aa: Vec<Id> = (0..n)
                .map(|l| g.mul2(rows[i][l], unconstrained[l]))
                .collect();
            let aa = g.add(&aa);
            g.sub(b_hat[i], aa)
        })
        .collect();
    (gram, residual)
}

/// `q̈ = a + W λ` and `Fᶜ = Âᵀ λ` (times the common mass) over the
/// multipliers' symbols.
fn motion(
    g: &mut Graph,
    rows: &[Vec<Id>],
    weighted: &[Vec<Id>],
    unconstrained: &[Id],
    common_mass: Option<Id>,
) -> (Vec<Id>, Vec<Id>) {
    let (n, k) = (unconstrained.len(), rows.len());
    let lambda: Vec<Id> = (0..k).map(|j| g.sym(Sym::Multiplier(j))).collect();
    let mut acceleration = Vec::with_capacity(n);
    let mut force = Vec::with_capacity(n);
    for i in 0..n {
        let mut acc = vec![unconstrained[i]];
        let mut f = Vec::with_capacity(k);
        for j in 0..k {
            acc.push(g.mul2(weighted[i][j], lambda[j]));
            f.push(g.mul2(rows[j][i], lambda[j]));
        }
        acceleration.push(g.add(&acc));
        let f = g.add(&f);
        force.push(match common_mass {
            Some(m) => g.mul2(m, f),
            None => f,
        });
    }
    (acceleration, force)
}

/// `1/c` for the numeric content `c` of a row of `A` (the rational
/// content of the entries' own contents: `2·x1 − 2·x2` has 2, `l·sin p/2`
/// has 1/2), or 1 where there is none to divide out.
fn row_scale(g: &Graph, row: &[Id]) -> Num {
    let entry_content = |e: Id| -> Option<Num> {
        match g.node(e) {
            Node::Num(n) => Some(*n),
            Node::Add(terms, c0) => {
                crate::expr::num::content(terms.iter().map(|t| t.1).chain(Some(*c0)))
            }
            _ => Some(Num::ONE),
        }
    };
    let contents: Option<Vec<Num>> = row
        .iter()
        .filter(|&&e| !g.is_zero(e))
        .map(|&e| entry_content(e))
        .collect();
    contents
        .and_then(crate::expr::num::content)
        .map(Num::recip)
        .filter(|d| matches!(d, Num::Rational(..)))
        .unwrap_or(Num::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_mass_is_inverted_exactly() {
        let m = vec![
            vec![Num::int(2), Num::int(1)],
            vec![Num::int(1), Num::int(2)],
        ];
        let inv = exact_inverse(&m).unwrap();
        assert_eq!(
            inv,
            vec![
                vec![Num::ratio(2, 3), Num::ratio(-1, 3)],
                vec![Num::ratio(-1, 3), Num::ratio(2, 3)]
            ]
        );
        assert!(exact_inverse(&[
            vec![Num::int(1), Num::int(2)],
            vec![Num::int(2), Num::int(4)]
        ])
        .is_none());
    }
}
