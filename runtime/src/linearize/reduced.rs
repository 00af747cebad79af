//! The linearization on the constraint manifold (the module docs of
//! [`linearize`](super) derive it): the reduced state, its basis of the
//! tangent space, and `δẋᵣ = a δxᵣ + b δu`.

use super::*;

/// The linearization on the constraint manifold: `δẋᵣ = a δxᵣ + b δu` for
/// the reduced state `xᵣ = (q[coordinates], q̇[speeds])`.
///
/// `coordinates` are the `n − r_h` coordinates the position-level
/// (holonomic) constraints leave free, `speeds` the `n − r` velocities all
/// constraints leave free (`r_h`, `r`: the generic ranks of the
/// position-level rows of `A` and of `A`). For holonomic constraints alone
/// both are the independent coordinates of the Gibbs–Appell partition and
/// `xᵣ = (q_I, q̇_I)`; for nonholonomic ones the state is every coordinate
/// and the independent speeds, the textbook form (Kane's dependent speeds).
/// Its eigenvalues are the physical ones: the constraint directions, which
/// give spurious zero eigenvalues in the full [`linearization`], are gone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduced<T, const NX: usize, const NU: usize, const NQ: usize, const NV: usize> {
    /// `∂ẋᵣ/∂xᵣ`.
    pub a: SMatrix<T, NX, NX>,
    /// `∂ẋᵣ/∂u`.
    pub b: SMatrix<T, NX, NU>,
    /// The indices of the coordinates kept, ascending.
    pub coordinates: [usize; NQ],
    /// The indices of the velocities kept, ascending.
    pub speeds: [usize; NV],
}

/// The indices `0..N` not in `taken`, ascending (`M = N − taken.len()`).
fn complement<const N: usize, const M: usize>(taken: &[usize]) -> [usize; M] {
    let mut out = [0usize; M];
    let mut next = 0;
    for i in 0..N {
        if !taken.contains(&i) {
            if let Some(slot) = out.get_mut(next) {
                *slot = i;
            }
            next += 1;
        }
    }
    out
}

/// `X` with `A[:, cols] X = rhs` for a consistent system (least squares
/// by the normal equations of the `R` chosen columns), `None` where those
/// columns are dependent or the system is not consistent to `√ε` of its
/// scale (checked after the solve).
fn solve_columns<
    T: RealField + Copy,
    const K: usize,
    const N: usize,
    const R: usize,
    const C: usize,
>(
    a: &SMatrix<T, K, N>,
    cols: &[usize; R],
    rhs: &SMatrix<T, K, C>,
) -> Option<SMatrix<T, R, C>> {
    let mut sub = SMatrix::<T, K, R>::zeros();
    for (j, &c) in cols.iter().enumerate() {
        sub.set_column(j, &a.column(c));
    }
    let gram = sub.transpose() * sub;
    let chol = Cholesky::new(gram)?;
    let x = chol.solve(&(sub.transpose() * rhs));
    let scale = sub.amax() * x.amax() + rhs.amax();
    let residual = (sub * x - rhs).amax();
    (residual <= T::default_epsilon().sqrt() * scale).then_some(x)
}

/// `start`, then greedily the most independent further columns of `a`
/// (modified Gram–Schmidt, largest residual first) until there are `R`;
/// `None` where fewer than `R` columns are independent (to `√ε` of `a`'s
/// largest entry), or `start` itself is dependent.
fn extend_independent<T: RealField + Copy, const K: usize, const N: usize, const R: usize>(
    a: &SMatrix<T, K, N>,
    start: &[usize],
) -> Option<[usize; R]> {
    let mut chosen = [0usize; R];
    let mut basis = [SVector::<T, K>::zeros(); R];
    let tolerance = T::default_epsilon().sqrt() * a.amax();
    for step in 0..R {
        let mut best: Option<(usize, SVector<T, K>, T)> = None;
        for c in 0..N {
            // The first steps take `start` in order; later ones any column.
            let allowed = start.get(step).is_none_or(|&s| s == c);
            if !allowed || chosen[..step].contains(&c) {
                continue;
            }
            let mut v: SVector<T, K> = a.column(c).into_owned();
            for e in &basis[..step] {
                v -= e * e.dot(&v);
            }
            let norm = v.norm();
            if best.as_ref().is_none_or(|(_, _, b)| norm > *b) {
                best = Some((c, v, norm));
            }
        }
        let (c, v, norm) = best?;
        // NaN counts as dependent.
        if norm.partial_cmp(&tolerance) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        chosen[step] = c;
        basis[step] = v / norm;
    }
    chosen.sort_unstable();
    Some(chosen)
}

/// The basis `T` (`N × M`) of `A[:, dependent] δ[dependent] =
/// −A[:, free] δ[free]` in the `free` components: the identity in the rows
/// `free`, `−A_D⁻¹ A_I` in the rows `dependent`; `None` where `A_D` is
/// singular.
fn tangent_basis<
    T: RealField + Copy,
    const K: usize,
    const N: usize,
    const R: usize,
    const M: usize,
>(
    a: &SMatrix<T, K, N>,
    dependent: &[usize; R],
    free: &[usize; M],
) -> Option<SMatrix<T, N, M>> {
    let mut a_i = SMatrix::<T, K, M>::zeros();
    for (j, &c) in free.iter().enumerate() {
        a_i.set_column(j, &a.column(c));
    }
    let x = solve_columns(a, dependent, &a_i)?;
    let mut basis = SMatrix::<T, N, M>::zeros();
    for (j, &c) in free.iter().enumerate() {
        basis[(c, j)] = T::one();
    }
    for (i, &d) in dependent.iter().enumerate() {
        for j in 0..M {
            basis[(d, j)] = -x[(i, j)];
        }
    }
    Some(basis)
}

/// The reduced linearization at `(q, q̇, t)` from the Jacobians there.
/// The dependent coordinates are chosen at this state, where they are best
/// conditioned: first `RH = N − NQ` columns of the position-level rows of
/// `A` (the coordinates the holonomic constraints fix), then as many more
/// of `A` as make `R = N − NV` (the speeds all constraints fix). Called
/// by the generated `linearize_reduced`.
///
/// With `T_q` the tangent of the position constraints (`δq = T_q δq[I_h]`),
/// `T_v` that of the velocity constraints and `W = −A_D⁺ ∂ψ/∂q` how the
/// dependent velocities move with `q` (`δq̇ = T_v δq̇[I] + W δq`):
///
/// ```text
/// a = [[(W T_q)[I_h],               T_v[I_h]],
///      [((J_q + J_q̇ W) T_q)[I],     (J_q̇ T_v)[I]]],   b = [[0], [J_u[I]]].
/// ```
#[allow(clippy::many_single_char_names, clippy::too_many_arguments)]
pub fn reduced<
    T,
    S,
    const N: usize,
    const K: usize,
    const NU: usize,
    const D: usize,
    const NQ: usize,
    const NV: usize,
    const NX: usize,
    const R: usize,
    const RH: usize,
>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    jac: &Jacobians<T, N, NU>,
) -> Result<Reduced<T, NX, NU, NQ, NV>, crate::DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    const {
        assert!(NX == NQ + NV && R + NV == N && RH + NQ == N && RH <= R);
    };
    let singular = crate::DynamicsError::SingularPartition;
    let (a, _) = system.constraint_matrices(q, qd, t);
    let psi_q = system.velocity_constraint_jacobian(q, qd, t);
    if !(a.iter().chain(psi_q.iter()).all(|x| x.is_finite()) && jac.is_finite()) {
        return Err(crate::DynamicsError::NonFinite);
    }
    let (a_h, fixed, eliminated) = dependents::<T, S, N, K, R, RH>(&a).ok_or(singular)?;
    // Speeds: A_D q̇[D] = −A_I q̇[I] − ψ_q δq, so δq̇ = T_v δq̇[I] + W δq.
    let speeds: [usize; NV] = complement::<N, NV>(&eliminated);
    let t_v = tangent_basis(&a, &eliminated, &speeds).ok_or(singular)?;
    let y = solve_columns(&a, &eliminated, &psi_q).ok_or(singular)?;
    let mut w = SMatrix::<T, N, N>::zeros();
    for (i, &d) in eliminated.iter().enumerate() {
        for j in 0..N {
            w[(d, j)] = -y[(i, j)];
        }
    }
    // Coordinates: A_H[:, fixed] δq[fixed] = −A_H[:, I_h] δq[I_h].
    let coordinates: [usize; NQ] = complement::<N, NQ>(&fixed);
    let t_q = tangent_basis(&a_h, &fixed, &coordinates).ok_or(singular)?;
    let wt = w * t_q;
    let lower_q = (jac.dq + jac.dqd * w) * t_q;
    let lower_v = jac.dqd * t_v;
    Ok(assemble(
        (coordinates, speeds),
        (&wt, &t_v),
        (&lower_q, &lower_v),
        &jac.du,
    ))
}

/// The dependent coordinates at `a`: `RH` fixed by the position-level rows
/// (`a_h`, the other rows zeroed, returned too), extended to `R` by all
/// rows; `None` where the rows do not have that rank.
#[allow(clippy::type_complexity)]
fn dependents<T, S, const N: usize, const K: usize, const R: usize, const RH: usize>(
    a: &SMatrix<T, K, N>,
) -> Option<(SMatrix<T, K, N>, [usize; RH], [usize; R])>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    let mut a_h = *a;
    for (r, level) in S::CONSTRAINT_LEVELS.iter().enumerate() {
        if *level != crate::ConstraintLevel::Position {
            a_h.row_mut(r).fill(T::zero());
        }
    }
    let fixed: [usize; RH] = extend_independent(&a_h, &[])?;
    let eliminated: [usize; R] = extend_independent(a, &fixed)?;
    Some((a_h, fixed, eliminated))
}

/// The reduced matrices from their blocks, rows of the full `N`: `a`'s
/// upper rows are the `coordinates`' rows of `[W T_q, T_v]`, its lower
/// rows the `speeds`' of `[(J_q + J_q̇ W) T_q, J_q̇ T_v]`, and `b`'s lower
/// rows the speeds' of `J_u` (its upper rows zero).
#[allow(clippy::type_complexity)]
fn assemble<
    T: RealField + Copy,
    const N: usize,
    const NX: usize,
    const NU: usize,
    const NQ: usize,
    const NV: usize,
>(
    (coordinates, speeds): ([usize; NQ], [usize; NV]),
    upper: (&SMatrix<T, N, NQ>, &SMatrix<T, N, NV>),
    lower: (&SMatrix<T, N, NQ>, &SMatrix<T, N, NV>),
    du: &SMatrix<T, N, NU>,
) -> Reduced<T, NX, NU, NQ, NV> {
    let mut out = Reduced {
        a: SMatrix::<T, NX, NX>::zeros(),
        b: SMatrix::<T, NX, NU>::zeros(),
        coordinates,
        speeds,
    };
    for (row, &c) in coordinates.iter().enumerate() {
        for j in 0..NQ {
            out.a[(row, j)] = upper.0[(c, j)];
        }
        for j in 0..NV {
            out.a[(row, NQ + j)] = upper.1[(c, j)];
        }
    }
    for (row, &c) in speeds.iter().enumerate() {
        for j in 0..NQ {
            out.a[(NQ + row, j)] = lower.0[(c, j)];
        }
        for j in 0..NV {
            out.a[(NQ + row, NQ + j)] = lower.1[(c, j)];
        }
        for j in 0..NU {
            out.b[(NQ + row, j)] = du[(c, j)];
        }
    }
    out
}
