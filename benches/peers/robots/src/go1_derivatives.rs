//! Our Jacobians of `q̈` and `λ` (`acceleration_jacobian`,
//! `multiplier_jacobian`) at a state of a free base on a quaternion,
//! turned into Pinocchio's conventions for `computeConstraintDynamicsDerivatives`.
//!
//! Ours are by the coordinates `q = (p, e, joints)` (`e = (w, x, y, z)`)
//! and their rates `q̇`; Pinocchio's by a displacement `δ = (δ_lin, δ_ang,
//! joints)` of the configuration (`p + R δ_lin`, `e ⊗ exp(δ_ang / 2)`) with
//! the velocity `v = (Rᵀ ṗ, ω, q̇_joints)` in the base's axes held, and of
//! `v`. With `q̇ = G(q) v` (`ṗ = R v_lin`, `ė = ½ e ⊗ (0, ω)`):
//!
//! - `∂q/∂δ = E`, `∂q̇/∂δ = Gδ` (`R (eᵢ × v_lin)` and `¼ e ⊗ (0, eᵢ) ⊗
//!   (0, ω)` for `δ_ang,i`), `∂q̇/∂v = G` (which equals `E`);
//! - `a = (Rᵀ p̈ − ω × v_lin, 2 (ē ⊗ ë)_vec, q̈_joints)`, whose own
//!   derivatives along `δ_ang,i` are `−eᵢ × Rᵀ p̈` and `2 (∂ē ⊗ ë)_vec`, and
//!   along `v` are `−ω × eᵢ`, `−eᵢ × v_lin`;
//! - `∂a/∂δ = Φ (J_q E + J_q̇ Gδ) + ∂Φ/∂δ`, `∂a/∂v = Φ J_q̇ G + ∂Φ/∂v`,
//!   `∂a/∂τ = Φ J_u` (`Φ` the linear map `q̈ ↦ a`), and `λ` the same
//!   without `Φ` (the feet's forces, world axes, as they are).

use constrained::nalgebra::{Matrix3, Quaternion, SMatrix, SVector, UnitQuaternion, Vector3};

/// Coordinates of a free base on twelve joints.
pub const N: usize = 19;
/// Tangent dimension.
pub const V: usize = 18;

/// Our Jacobians in Pinocchio's conventions (its joints in our order).
pub struct Derivatives {
    pub da_dq: SMatrix<f64, V, V>,
    pub da_dv: SMatrix<f64, V, V>,
    pub da_dtau: SMatrix<f64, V, 12>,
    pub dl_dq: SMatrix<f64, 12, V>,
    pub dl_dv: SMatrix<f64, 12, V>,
    pub dl_dtau: SMatrix<f64, 12, 12>,
}

fn pure(v: Vector3<f64>) -> Quaternion<f64> {
    Quaternion::new(0.0, v.x, v.y, v.z)
}

/// `(w, x, y, z)` of `q`.
fn four(q: Quaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// The base's attitude `e`, `R`, `v_lin = Rᵀ ṗ` and `ω = 2 (ē ⊗ ė)_vec`.
pub fn base(
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> (Quaternion<f64>, Matrix3<f64>, Vector3<f64>, Vector3<f64>) {
    let e = Quaternion::new(q[3], q[4], q[5], q[6]);
    let r = UnitQuaternion::from_quaternion(e)
        .to_rotation_matrix()
        .into_inner();
    let pd = Vector3::new(qd[0], qd[1], qd[2]);
    let ed = Quaternion::new(qd[3], qd[4], qd[5], qd[6]);
    (e, r, r.transpose() * pd, (e.conjugate() * ed).imag() * 2.0)
}

/// `(E, Gδ)`: `∂q/∂δ` (also `∂q̇/∂v`) and `∂q̇/∂δ` at fixed `v`.
fn maps(
    e: Quaternion<f64>,
    r: &Matrix3<f64>,
    (v_lin, w): (Vector3<f64>, Vector3<f64>),
) -> (SMatrix<f64, N, V>, SMatrix<f64, N, V>) {
    let mut map = SMatrix::<f64, N, V>::zeros();
    let mut rates = SMatrix::<f64, N, V>::zeros();
    map.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
    for i in 0..3 {
        let axis = Vector3::ith(i, 1.0);
        let turn = e * pure(axis) * 0.5;
        for (k, x) in four(turn).into_iter().enumerate() {
            map[(3 + k, 3 + i)] = x;
        }
        rates
            .fixed_view_mut::<3, 1>(0, 3 + i)
            .copy_from(&(r * axis.cross(&v_lin)));
        for (k, x) in four(turn * pure(w) * 0.5).into_iter().enumerate() {
            rates[(3 + k, 3 + i)] = x;
        }
    }
    for j in 0..12 {
        map[(7 + j, 6 + j)] = 1.0;
    }
    (map, rates)
}

/// `Φ x`: a change `x` of `q̈` as one of `a` (the base's `Rᵀ p̈` and
/// `2 (ē ⊗ ẍ_e)_vec`, the joints' as they are).
fn phi(e: Quaternion<f64>, r: &Matrix3<f64>, x: &SVector<f64, N>) -> SVector<f64, V> {
    let mut out = SVector::<f64, V>::zeros();
    let lin = r.transpose() * Vector3::new(x[0], x[1], x[2]);
    let ang = (e.conjugate() * Quaternion::new(x[3], x[4], x[5], x[6])).imag() * 2.0;
    out.fixed_rows_mut::<3>(0).copy_from(&lin);
    out.fixed_rows_mut::<3>(3).copy_from(&ang);
    for j in 0..12 {
        out[6 + j] = x[7 + j];
    }
    out
}

/// Our Jacobians `(J_q, J_q̇, J_u)` of `q̈` and `(L_q, L_q̇, L_u)` of `λ`
/// (the feet's twelve rows first) at `(q, q̇)` with the solved `q̈`, in
/// Pinocchio's conventions (module docs).
#[allow(clippy::type_complexity)]
pub fn pinocchio_derivatives(
    (q, qd, qdd): (&SVector<f64, N>, &SVector<f64, N>, &SVector<f64, N>),
    jac: (
        &SMatrix<f64, N, N>,
        &SMatrix<f64, N, N>,
        &SMatrix<f64, N, 12>,
    ),
    lam: (
        &SMatrix<f64, 13, N>,
        &SMatrix<f64, 13, N>,
        &SMatrix<f64, 13, 12>,
    ),
) -> Derivatives {
    let (e, r, v_lin, w) = base(q, qd);
    let (map, rates) = maps(e, &r, (v_lin, w));
    let by_q = jac.0 * map + jac.1 * rates;
    let by_v = jac.1 * map;
    let apply = |m: &SMatrix<f64, N, V>| {
        SMatrix::<f64, V, V>::from_columns(
            &(0..V)
                .map(|c| phi(e, &r, &m.column(c).into_owned()))
                .collect::<Vec<_>>(),
        )
    };
    let mut da_dq = apply(&by_q);
    let mut da_dv = apply(&by_v);
    let da_dtau = SMatrix::<f64, V, 12>::from_columns(
        &(0..12)
            .map(|c| phi(e, &r, &jac.2.column(c).into_owned()))
            .collect::<Vec<_>>(),
    );
    let body_pdd = r.transpose() * Vector3::new(qdd[0], qdd[1], qdd[2]);
    let edd = Quaternion::new(qdd[3], qdd[4], qdd[5], qdd[6]);
    for i in 0..3 {
        let axis = Vector3::ith(i, 1.0);
        // Along δ_ang,i: Rᵀ turns by −eᵢ×, ē by −½ (0, eᵢ) ⊗ ē.
        let lin = -axis.cross(&body_pdd);
        let turned = (e * pure(axis) * 0.5).conjugate();
        let ang = (turned * edd).imag() * 2.0;
        for k in 0..3 {
            da_dq[(k, 3 + i)] += lin[k];
            da_dq[(3 + k, 3 + i)] += ang[k];
        }
        // Along v: −ω × v_lin's own derivatives.
        let by_lin = -w.cross(&axis);
        let by_ang = -axis.cross(&v_lin);
        for k in 0..3 {
            da_dv[(k, i)] += by_lin[k];
            da_dv[(k, 3 + i)] += by_ang[k];
        }
    }
    let feet = |m: SMatrix<f64, 13, V>| m.fixed_rows::<12>(0).into_owned();
    Derivatives {
        da_dq,
        da_dv,
        da_dtau,
        dl_dq: feet(lam.0 * map + lam.1 * rates),
        dl_dv: feet(lam.1 * map),
        dl_dtau: lam.2.fixed_rows::<12>(0).into_owned(),
    }
}

/// The state reached from `(q, q̇)` by Pinocchio's displacement `h` along
/// tangent direction `c` (`dv = false`) or by `h` on `v`'s entry `c`
/// (`dv = true`), `v` otherwise held: for central differences.
pub fn displaced(
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    c: usize,
    h: f64,
    dv: bool,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let (e, r, mut v_lin, mut w) = base(q, qd);
    let (mut q, mut qd) = (*q, *qd);
    let mut e = e;
    if dv {
        match c {
            0..=2 => v_lin[c] += h,
            3..=5 => w[c - 3] += h,
            _ => qd[c + 1] += h,
        }
    } else {
        match c {
            0..=2 => {
                let p = r * Vector3::ith(c, h);
                for k in 0..3 {
                    q[k] += p[k];
                }
            }
            3..=5 => {
                let turn = UnitQuaternion::from_scaled_axis(Vector3::ith(c - 3, h));
                e *= turn.into_inner();
                for (k, x) in four(e).into_iter().enumerate() {
                    q[3 + k] = x;
                }
            }
            _ => q[c + 1] += h,
        }
    }
    let r = UnitQuaternion::from_quaternion(e)
        .to_rotation_matrix()
        .into_inner();
    let pd = r * v_lin;
    let ed = e * pure(w) * 0.5;
    for k in 0..3 {
        qd[k] = pd[k];
    }
    for (k, x) in four(ed).into_iter().enumerate() {
        qd[3 + k] = x;
    }
    (q, qd)
}

/// Pinocchio's `a` from ours at `(q, q̇)`: `(Rᵀ p̈ − ω × v_lin, 2 (ē ⊗
/// ë)_vec, q̈_joints)`.
pub fn acceleration(
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    qdd: &SVector<f64, N>,
) -> SVector<f64, V> {
    let (e, r, v_lin, w) = base(q, qd);
    let mut a = phi(e, &r, qdd);
    let coriolis = w.cross(&v_lin);
    for k in 0..3 {
        a[k] -= coriolis[k];
    }
    a
}
