//! Linearization: the exact Jacobians of `q̈(q, q̇, u)`, the linear model
//! `δẋ = A δx + B δu` in all coordinates, and the reduced one on the
//! constraint manifold.
//!
//! # The tangent systems
//!
//! `q̈` solves `M q̈ = F + Aᵀλ`, `A q̈ = b`. Differentiating both by one
//! variable `v` (a coordinate, a velocity or an input) gives the same
//! constrained system for `q̈ᵥ = ∂q̈/∂v`:
//!
//! ```text
//! M q̈ᵥ = F̃ᵥ + Aᵀλᵥ,   A q̈ᵥ = b̃ᵥ,
//! F̃ᵥ = ∂F/∂v − (∂M/∂v) q̈ + (∂A/∂v)ᵀ λ,   b̃ᵥ = ∂b/∂v − (∂A/∂v) q̈.
//! ```
//!
//! The macro differentiates `F`, `M`, `A` and `b` symbolically at compile
//! time and emits `F̃`, `b̃` for every column (`tangent_rhs`); here `M` and
//! `S = A M⁻¹ Aᵀ` are factored once (Cholesky; the rank-revealing
//! [`PivotedLdlt`] of `S` with the rank rule of `acceleration`) and every
//! column is one solve: `q̈ᵥ = M⁻¹F̃ᵥ + M⁻¹Aᵀ S⁺(b̃ᵥ − A M⁻¹F̃ᵥ)`, where
//! every row is kept regrouped as `q̈ᵥ = P F̃ᵥ + Q b̃ᵥ` with `P` and `Q`
//! formed once (`batch`). Nothing is differenced.
//!
//! `λ` is recovered from the constraint force the solver returned,
//! `λ = S⁺ A M⁻¹ Fᶜ`; any `λ` with `Aᵀλ = Fᶜ` gives the same `q̈ᵥ` (the
//! difference lies in the null space of `Aᵀ`, which the solve projects
//! out), so redundant constraints behave. Where the rank decision drops
//! rows of a consistent `A`, the result is the Jacobian of the `q̈`
//! actually returned: the minimiser over the rows kept, whose tangent
//! system is solved with the same {1}-inverse. A semi-definite `M` is
//! solved through its auxiliary mass `M + s AᵀA`, whose tangent system
//! is the one above with `F̃ᵥ + s Aᵀ b̃ᵥ` (the `∂s` terms multiply
//! `A q̈ − b = 0`).

use crate::generated::{all_finite, auxiliary_mass, Generated, Motion};
use crate::inverse::PivotedLdlt;
use crate::rank::{consistency_tolerance, safe_minimum, tight_cut};
use crate::svd::JacobiSvd;
use crate::DynamicsError;
use batch::Projection;
use nalgebra::{Cholesky, Const, RealField, SMatrix, SVector};

/// The Jacobians of `q̈(q, q̇, u)`: `dq = ∂q̈/∂q`, `dqd = ∂q̈/∂q̇`,
/// `du = ∂q̈/∂u`, column `j` the derivative by the `j`-th coordinate,
/// velocity or input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jacobians<T, const N: usize, const NU: usize> {
    /// `∂q̈/∂q`.
    pub dq: SMatrix<T, N, N>,
    /// `∂q̈/∂q̇`.
    pub dqd: SMatrix<T, N, N>,
    /// `∂q̈/∂u`.
    pub du: SMatrix<T, N, NU>,
}

impl<T: RealField + Copy, const N: usize, const NU: usize> Jacobians<T, N, NU> {
    /// All zero: the generated code writes the columns in place.
    #[must_use]
    pub fn zeros() -> Self {
        Jacobians {
            dq: SMatrix::zeros(),
            dqd: SMatrix::zeros(),
            du: SMatrix::zeros(),
        }
    }

    /// Every entry NaN: what the total (plain-valued) `acceleration_jacobian`
    /// of a system whose `acceleration` cannot fail returns where its
    /// `try_acceleration_jacobian` is an `Err` (the derivative does not
    /// exist, cannot be trusted or overflows).
    #[must_use]
    pub fn not_a_number() -> Self {
        let nan = T::zero() / T::zero();
        Jacobians {
            dq: SMatrix::from_element(nan),
            dqd: SMatrix::from_element(nan),
            du: SMatrix::from_element(nan),
        }
    }

    /// Whether every entry is finite.
    // Always inlined: the generated Jacobians end in this check, and
    // inlined into their AVX copies it runs on four entries a vector.
    #[must_use]
    #[inline(always)]
    pub fn is_finite(&self) -> bool {
        all_finite(self.dq.as_slice())
            & all_finite(self.dqd.as_slice())
            & all_finite(self.du.as_slice())
    }
}

/// What the generated code provides for the Jacobian: the right-hand sides
/// of the tangent systems. Implemented by `constrained_system!`.
#[doc(hidden)]
pub trait Tangent<T: RealField + Copy, const N: usize, const K: usize, const D: usize> {
    /// Writes `(F̃, b̃)`, one column per variable (coordinates, velocities,
    /// inputs), into `f` and `b`: their structural nonzeros only, so the
    /// caller passes zeros. In place, because for a large system these
    /// mostly zero matrices are bigger than the work on them.
    #[allow(clippy::too_many_arguments)]
    fn tangent_rhs(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        qdd: &SVector<T, N>,
        lam: &SVector<T, K>,
        f: &mut SMatrix<T, N, D>,
        b: &mut SMatrix<T, K, D>,
    );
    /// `∂ψ/∂q` of the velocity-level constraints `ψ` (`φ̇` or `φ`).
    fn velocity_constraint_jacobian(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
    ) -> SMatrix<T, K, N>;
}

/// `M⁻¹` applied by Cholesky, or, where `M` is not numerically positive
/// definite (possible only for states where `acceleration` already
/// answered by other means), by the rank-revealing `LDLᵀ`.
enum MassSolve<T: RealField + Copy, const N: usize> {
    Cholesky(Cholesky<T, Const<N>>),
    Ldlt(PivotedLdlt<T, N>),
}

impl<T: RealField + Copy, const N: usize> MassSolve<T, N> {
    fn new(m: SMatrix<T, N, N>) -> Self {
        match Cholesky::new(m) {
            Some(c) => MassSolve::Cholesky(c),
            None => MassSolve::Ldlt(PivotedLdlt::factor(&m)),
        }
    }

    fn solve(&self, v: &SVector<T, N>) -> SVector<T, N> {
        match self {
            MassSolve::Cholesky(c) => c.solve(v),
            MassSolve::Ldlt(l) => l.solve_unchecked(v),
        }
    }

    /// `M⁻¹`: `L⁻ᵀ L⁻¹` from the Cholesky factor's inverse, where the
    /// solves of the identity's columns cost three times as much (nalgebra's
    /// `Cholesky::solve` was a third of the Go1's Jacobians); by those
    /// solves for the `LDLᵀ`.
    fn inverse(&self) -> SMatrix<T, N, N> {
        match self {
            MassSolve::Cholesky(c) => {
                let x = batch::lower_inverse(&c.l());
                batch::lower_gram(&x)
            }
            MassSolve::Ldlt(l) => l.inverse_unchecked(),
        }
    }
}

/// The dense pieces of the tangent systems at `(q, q̇, t)`: `A`, the `M`
/// factored (a semi-definite `M`'s auxiliary mass `M + s AᵀA`, with `s`),
/// `W = M⁻¹ Aᵀ` and `S = A W` with its pivoted `LDLᵀ`, one factorization of
/// each.
struct Dense<T: RealField + Copy, const N: usize, const K: usize> {
    a: SMatrix<T, K, N>,
    m: SMatrix<T, N, N>,
    s: T,
    mass: MassSolve<T, N>,
    inverse: SMatrix<T, N, N>,
    w: SMatrix<T, N, K>,
    gram: SMatrix<T, K, K>,
    ldlt: PivotedLdlt<T, K>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> Dense<T, N, K> {
    /// `Err(NonFinite)` where `M` is in the range where products
    /// underflow: a rigid body's `M = 4 Gᵀ J G` at `e = 1e-154` is 4e-308,
    /// which has lost its digits, and so have the tangent terms made from
    /// it: no derivative to trust.
    fn new<S: Generated<T, N, K>>(
        system: &S,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
    ) -> Result<Self, DynamicsError> {
        let (a, _) = system.constraint_matrices(q, qd, t);
        let m = system.mass_matrix(q, t);
        let (m, s) = if S::SEMIDEFINITE_MASS {
            auxiliary_mass(&m, &a)
        } else {
            (m, T::one())
        };
        if m.diagonal().iter().any(|&x| x.abs() < safe_minimum()) {
            return Err(DynamicsError::NonFinite);
        }
        let mass = MassSolve::new(m);
        let inverse = mass.inverse();
        let w = batch::times_transpose(&inverse, &a);
        let gram = batch::gram(&a, &w);
        let ldlt = PivotedLdlt::factor(&gram);
        Ok(Dense {
            a,
            m,
            s,
            mass,
            inverse,
            w,
            gram,
            ldlt,
        })
    }
}

/// [`try_acceleration_jacobian`] with its `Err` as every entry NaN
/// ([`Jacobians::not_a_number`]).
#[must_use]
pub fn acceleration_jacobian<
    T,
    S,
    const N: usize,
    const K: usize,
    const NU: usize,
    const D: usize,
>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    motion: Motion<T, N>,
) -> Jacobians<T, N, NU>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    try_acceleration_jacobian::<T, S, N, K, NU, D>(system, q, qd, t, motion)
        .unwrap_or_else(|_| Jacobians::not_a_number())
}

/// The Jacobians of `q̈` at `(q, q̇, t)`, given the motion `(q̈, Fᶜ)` the
/// system's solver returned there. Called by the generated
/// `acceleration_jacobian` where its own solve's rank decision is suspect;
/// `D = 2N + NU` columns.
///
/// `Err(NotDifferentiable)` where `q̈` has no derivative `T` can resolve:
/// `A` has lost rank to rounding level (Appell's particle at rest, `q̇ = 0`,
/// where `A = [ẋ, ẏ, −ż]` vanishes and `q̈`, homogeneous of degree one in
/// `q̇`, has a derivative in no direction), or the rank decision behind
/// `acceleration` is too close to call for its derivative to hold
/// (`recomputed_jacobian`). `Err(NonFinite)` where `M` or a row of `A` has
/// lost its digits to underflow, or the solve cannot be done. The entries
/// of an `Ok` are not checked for finiteness here (the generated caller
/// checks its result once, whichever solve gave it).
#[allow(clippy::many_single_char_names)]
pub fn try_acceleration_jacobian<
    T,
    S,
    const N: usize,
    const K: usize,
    const NU: usize,
    const D: usize,
>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    motion: Motion<T, N>,
) -> Result<Jacobians<T, N, NU>, DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    const { assert!(D == 2 * N + NU, "D = 2N + NU columns") };
    let (qdd, force) = motion;
    let Dense {
        a,
        m,
        s,
        mass,
        inverse,
        w,
        gram,
        ldlt,
    } = Dense::new(system, q, qd, t)?;
    // Where the fast solve's rank decision is suspect (`crate::rank`),
    // `acceleration` checked it and kept the rows it must: differentiate
    // that `q̈` the way it was recomputed.
    let underflow = gram.diagonal().iter().any(|&x| x < safe_minimum());
    let dropped = ldlt.rank() < S::GENERIC_RANK;
    if K > 0 && (underflow || dropped) {
        let branch = dropped && !underflow;
        return recomputed_jacobian::<T, S, N, K, NU, D>(
            system, q, qd, t, &m, s, &a, motion, branch,
        );
    }
    // λ with Aᵀλ = Fᶜ: S λ = A M⁻¹ Fᶜ = Wᵀ Fᶜ.
    let lam = ldlt.solve_unchecked(&(w.transpose() * force));
    if ldlt.rank() == K {
        let auxiliary = S::SEMIDEFINITE_MASS.then_some(s);
        let projection = Projection::new(&inverse, &w, &ldlt, auxiliary);
        let (jacobians, _) =
            projection.jacobians::<S, NU, D>(system, (q, qd, t), (&qdd, &lam), false);
        return Ok(jacobians);
    }
    let solve = |f_c: &SVector<T, N>, b_c: &SVector<T, K>| {
        let unconstrained = mass.solve(f_c);
        let mu = ldlt.solve_unchecked(&(b_c - a * unconstrained));
        Some(unconstrained + w * mu)
    };
    tangent_columns::<T, S, N, K, NU, D>(system, (q, qd, t), (&qdd, &lam), (&a, s), solve)
        .ok_or(DynamicsError::NonFinite)
}

/// The Jacobians column by column: the right-hand sides `F̃`, `b̃` of the
/// tangent systems at `(q, q̇, t)` with `q̈` and `λ` (for a semi-definite
/// `M`, the auxiliary system's `F̃ + s Aᵀ b̃` with `a`, `s`), each column
/// solved by `solve(f, b)` for its column of `∂q̈` (`None` if one fails).
#[allow(clippy::type_complexity)]
fn tangent_columns<T, S, const N: usize, const K: usize, const NU: usize, const D: usize>(
    system: &S,
    (q, qd, t): (&SVector<T, N>, &SVector<T, N>, T),
    (qdd, lam): (&SVector<T, N>, &SVector<T, K>),
    (a, s): (&SMatrix<T, K, N>, T),
    solve: impl FnMut(&SVector<T, N>, &SVector<T, K>) -> Option<SVector<T, N>>,
) -> Option<Jacobians<T, N, NU>>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    let (dq, dqd, du) =
        tangent_solutions::<T, S, N, K, NU, D, N>(system, (q, qd, t), (qdd, lam), (a, s), solve)?;
    Some(Jacobians { dq, dqd, du })
}

/// The tangent systems' solutions column by column, `R` entries each (`q̈ᵥ`
/// or `λᵥ`), as `(by q, by q̇, by u)`: the right-hand sides of
/// [`tangent_columns`], each solved by `solve(f, b)` (`None` if one fails).
#[allow(clippy::type_complexity)]
pub(crate) fn tangent_solutions<
    T,
    S,
    const N: usize,
    const K: usize,
    const NU: usize,
    const D: usize,
    const R: usize,
>(
    system: &S,
    (q, qd, t): (&SVector<T, N>, &SVector<T, N>, T),
    (qdd, lam): (&SVector<T, N>, &SVector<T, K>),
    (a, s): (&SMatrix<T, K, N>, T),
    mut solve: impl FnMut(&SVector<T, N>, &SVector<T, K>) -> Option<SVector<T, R>>,
) -> Option<(SMatrix<T, R, N>, SMatrix<T, R, N>, SMatrix<T, R, NU>)>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    let mut f_tilde = SMatrix::<T, N, D>::zeros();
    let mut b_tilde = SMatrix::<T, K, D>::zeros();
    system.tangent_rhs(q, qd, t, qdd, lam, &mut f_tilde, &mut b_tilde);
    let mut dq = SMatrix::<T, R, N>::zeros();
    let mut dqd = SMatrix::<T, R, N>::zeros();
    let mut du = SMatrix::<T, R, NU>::zeros();
    for c in 0..D {
        let b_c: SVector<T, K> = b_tilde.column(c).into_owned();
        let mut f_c: SVector<T, N> = f_tilde.column(c).into_owned();
        if S::SEMIDEFINITE_MASS {
            f_c += a.transpose() * (b_c * s);
        }
        let x = solve(&f_c, &b_c)?;
        if c < N {
            dq.set_column(c, &x);
        } else if c < 2 * N {
            dqd.set_column(c - N, &x);
        } else {
            du.set_column(c - 2 * N, &x);
        }
    }
    Some((dq, dqd, du))
}

/// The Jacobians where `acceleration`'s fast solve dropped more rows than
/// the model's redundancy (or `S` underflowed), so that `acceleration`
/// checked its answer and, near a branch point, recomputed it with the
/// rows kept ([`crate::rank::checked`]). Whichever it returned satisfies
/// every row of `A q̈ = b` (or it was an `Err`); where `A` keeps its
/// generic rank to rounding level, that `q̈` is the unique solution of
/// Gauss's principle with every row, on both sides of the fast solve's
/// threshold, and its derivative solves the tangent systems with every
/// row: by the row-scaled SVD the recomputation uses, `q̈ᵥ = uᵥ + L⁻ᵀ X⁺
/// D (b̃ᵥ − A uᵥ)`, `X = D A L⁻ᵀ`, `uᵥ = M⁻¹F̃ᵥ`, with the same cut (no
/// squaring of `A`: at `θ = 1e-8` the four-bar's `S` has lost every digit
/// of its smallest pivot, `X` none). `λ` solves `Xᵀ ν = L⁻¹ Fᶜ`, `λ = D ν`.
///
/// Checked after the fact where the fast solve dropped a row (`branch`):
/// `acceleration` keeps the fast solve's `q̈` wherever the dropped row
/// holds to [`consistency_tolerance`] `c`, so within a slab about the
/// consistent states it follows the rows kept, whose derivative differs
/// from the one with every row by order `1/θ`, and outside it the
/// recomputation: `acceleration` jumps, across the slab, by up to `c κ` of
/// `q̈` (`κ = σ₁/σ_r` of `X`, the conditioning of the rank decision). Where
/// that exceeds `√ε` the derivative is no property of `acceleration` that
/// `T` resolves: central differences give either answer depending on the
/// step (the four-bar at `θ = 1e-8`, `κ = 4e8`: `∂p̈₁/∂p₁ = 5.6e8` for steps
/// above 1e-12, 2.66 below 1e-13), and the result is
/// `Err(NotDifferentiable)`. The bound holds for `θ ≥ 1e-4` there
/// (`c κ = 9e-9`) and fails from `3e-5`; in `f32` (`c = 1.2e-4`) wherever
/// a row was dropped.
///
/// `Err(NotDifferentiable)` also where `A` has lost rank to rounding level
/// (at the branch point itself `q̈` is not differentiable);
/// `Err(NonFinite)` where a row has lost its digits to underflow or the
/// solve cannot be done.
#[allow(clippy::too_many_arguments, clippy::many_single_char_names)]
fn recomputed_jacobian<T, S, const N: usize, const K: usize, const NU: usize, const D: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    m: &SMatrix<T, N, N>,
    s: T,
    a: &SMatrix<T, K, N>,
    motion: Motion<T, N>,
    branch: bool,
) -> Result<Jacobians<T, N, NU>, DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    let non_finite = DynamicsError::NonFinite;
    let (qdd, force) = motion;
    if !(m.iter().chain(a.iter()).all(|x| x.is_finite())) {
        return Err(non_finite);
    }
    let chol = Cholesky::new(*m).ok_or(non_finite)?;
    let l = chol.l();
    let (scaled, largest) = scaled_rows(a).ok_or(non_finite)?;
    let xt = l
        .solve_lower_triangular(&scaled.transpose())
        .ok_or(non_finite)?;
    let svd = JacobiSvd::new(&xt.transpose()).ok_or(non_finite)?;
    let sigma = svd.singular_values();
    let cut = tight_cut::<T, N, K>() * sigma.max();
    let kept = sigma.iter().filter(|&&x| x > cut).count();
    if kept < S::GENERIC_RANK {
        return Err(DynamicsError::NotDifferentiable);
    }
    let mut sorted = sigma;
    sorted
        .as_mut_slice()
        .sort_unstable_by(|x, y| y.partial_cmp(x).unwrap_or(core::cmp::Ordering::Equal));
    let mut cut = cut;
    if S::GENERIC_RANK < K {
        cut = cut.max(sorted[S::GENERIC_RANK]);
    }
    // The rank decision's conditioning (doc comment): c σ₁ against √ε σ_r.
    if branch && S::GENERIC_RANK > 0 {
        let weakest = sorted[S::GENERIC_RANK - 1];
        if consistency_tolerance::<T>() * sorted[0] > T::default_epsilon().sqrt() * weakest {
            return Err(DynamicsError::NotDifferentiable);
        }
    }
    let transposed = JacobiSvd::new(&xt).ok_or(non_finite)?;
    let rhs = l.solve_lower_triangular(&force).ok_or(non_finite)?;
    let nu = transposed.solve(&rhs, cut).ok_or(non_finite)?;
    let lam = nu.component_div(&largest);
    let solve = |f_c: &SVector<T, N>, b_c: &SVector<T, K>| {
        let u = chol.solve(f_c);
        let r = (b_c - a * u).component_div(&largest);
        let y = svd.solve(&r, cut)?;
        let z = l.transpose().solve_upper_triangular(&y)?;
        Some(u + z)
    };
    let jac = tangent_columns::<T, S, N, K, NU, D>(system, (q, qd, t), (&qdd, &lam), (a, s), solve)
        .ok_or(non_finite)?;
    if jac.is_finite() {
        Ok(jac)
    } else {
        Err(non_finite)
    }
}

/// `(D A, diag D⁻¹)`: each row of `a` scaled to unit largest entry (by
/// division: a subnormal row's reciprocal overflows), a zero row left as
/// it is; `None` where a row's largest entry is subnormal (`f32` at 1e-40:
/// the row has lost its digits).
#[allow(clippy::type_complexity)]
fn scaled_rows<T: RealField + Copy, const K: usize, const N: usize>(
    a: &SMatrix<T, K, N>,
) -> Option<(SMatrix<T, K, N>, SVector<T, K>)> {
    let mut scaled = *a;
    let mut largest = SVector::<T, K>::from_element(T::one());
    // 2^-1022 in f64 (4 over the largest value); NaN, so never below, for
    // a `T` without one.
    let smallest_normal = nalgebra::convert::<f64, T>(4.0) / crate::generated::largest::<T>();
    for i in 0..K {
        let x = scaled.row(i).amax();
        if x > T::zero() && x < smallest_normal {
            return None;
        }
        if x > T::zero() {
            scaled.row_mut(i).unscale_mut(x);
            largest[i] = x;
        }
    }
    Some((scaled, largest))
}

/// `(A, B)` of `δẋ = A δx + B δu` for `x = (q, q̇)`:
/// `A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]`, `B = [[0], [∂q̈/∂u]]`. `N2 = 2N`.
#[must_use]
pub fn linearization<T: RealField + Copy, const N: usize, const NU: usize, const N2: usize>(
    j: &Jacobians<T, N, NU>,
) -> (SMatrix<T, N2, N2>, SMatrix<T, N2, NU>) {
    const { assert!(N2 == 2 * N, "N2 = 2N") };
    let mut a = SMatrix::<T, N2, N2>::zeros();
    let mut b = SMatrix::<T, N2, NU>::zeros();
    for i in 0..N {
        a[(i, N + i)] = T::one();
        for c in 0..N {
            a[(N + i, c)] = j.dq[(i, c)];
            a[(N + i, N + c)] = j.dqd[(i, c)];
        }
        for c in 0..NU {
            b[(N + i, c)] = j.du[(i, c)];
        }
    }
    (a, b)
}

mod batch;
mod multipliers;
mod reduced;
pub use multipliers::{
    try_acceleration_and_multiplier_jacobians, try_multiplier_jacobian, MultiplierJacobians,
};
pub use reduced::{reduced, Reduced};
