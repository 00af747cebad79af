//! States of a body on a free joint (`joint: free(x, y, z, qw, qx, qy, qz)`
//! in `bodies`): its seven coordinates are the position of its origin and
//! the unit quaternion `(w, x, y, z)` of its attitude, both in its parent's
//! joint frame (the world's, for a floating base), and their rates `q̇`.
//! [`FreeMotion`] turns a pose and a twist into those fourteen numbers and
//! back: `q̇_quat = ½ (0, ω) ⊗ q` with `ω` in the parent's frame, which
//! satisfies the norm's velocity constraint `qᵀ q̇_quat = 0` exactly.
//!
//! ```
//! use constrained_runtime::floating::FreeMotion;
//! use nalgebra::{SVector, UnitQuaternion, Vector3};
//!
//! let base = FreeMotion {
//!     position: Vector3::new(0.0, 0.0, 0.3),
//!     orientation: UnitQuaternion::from_euler_angles(0.1, 0.0, 0.0),
//!     linear: Vector3::new(0.5, 0.0, 0.0),
//!     angular: Vector3::new(0.0, 0.0, 1.0),
//! };
//! let (mut q, mut qd) = (SVector::<f64, 9>::zeros(), SVector::<f64, 9>::zeros());
//! base.write(0, &mut q, &mut qd).unwrap();
//! let back = FreeMotion::read(0, &q, &qd).unwrap();
//! assert!((back.angular - base.angular).norm() < 1e-15);
//! assert!((back.body_angular() - base.orientation.inverse() * base.angular).norm() < 1e-15);
//! ```

use nalgebra::{Quaternion, RealField, SVector, UnitQuaternion, Vector3};

/// Why a free joint's coordinates cannot be written or read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FreeJointError {
    /// The seven coordinates from `at` do not fit in the state.
    OutOfRange,
    /// The quaternion is zero or not finite: it has no attitude.
    NoAttitude,
}

impl core::fmt::Display for FreeJointError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            FreeJointError::OutOfRange => "the free joint's 7 coordinates do not fit in the state",
            FreeJointError::NoAttitude => "the free joint's quaternion is zero or not finite",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for FreeJointError {}

/// The pose and twist of a body on a free joint, in its parent's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeMotion<T: RealField + Copy> {
    /// The position of the body's origin.
    pub position: Vector3<T>,
    /// Its attitude: body axes → parent axes.
    pub orientation: UnitQuaternion<T>,
    /// The velocity of its origin, in the parent's axes.
    pub linear: Vector3<T>,
    /// Its angular velocity, in the parent's axes.
    pub angular: Vector3<T>,
}

impl<T: RealField + Copy> FreeMotion<T> {
    /// At rest at a pose.
    pub fn at_rest(position: Vector3<T>, orientation: UnitQuaternion<T>) -> Self {
        FreeMotion {
            position,
            orientation,
            linear: Vector3::zeros(),
            angular: Vector3::zeros(),
        }
    }

    /// The angular velocity in the body's own axes, `Rᵀ ω`.
    pub fn body_angular(&self) -> Vector3<T> {
        self.orientation.inverse_transform_vector(&self.angular)
    }

    /// The velocity of the origin in the body's own axes, `Rᵀ v`.
    pub fn body_linear(&self) -> Vector3<T> {
        self.orientation.inverse_transform_vector(&self.linear)
    }

    /// Writes the joint's seven coordinates `(x, y, z, qw, qx, qy, qz)` at
    /// `at` of `q`, and their rates at `at` of `qd`; the rest is left as is.
    pub fn write<const N: usize>(
        &self,
        at: usize,
        q: &mut SVector<T, N>,
        qd: &mut SVector<T, N>,
    ) -> Result<(), FreeJointError> {
        if at.checked_add(7).is_none_or(|end| end > N) {
            return Err(FreeJointError::OutOfRange);
        }
        let e = self.orientation.quaternion();
        let half = T::one() / (T::one() + T::one());
        let rate = Quaternion::from_imag(self.angular) * *e * half;
        let pose = [e.w, e.i, e.j, e.k];
        let rates = [rate.w, rate.i, rate.j, rate.k];
        for k in 0..3 {
            q[at + k] = self.position[k];
            qd[at + k] = self.linear[k];
        }
        for k in 0..4 {
            q[at + 3 + k] = pose[k];
            qd[at + 3 + k] = rates[k];
        }
        Ok(())
    }

    /// Reads the joint's pose and twist from the coordinates at `at`: the
    /// attitude is the quaternion normalised, the angular velocity
    /// `ω = 2 (q̇ ⊗ q̄)_vec / |q|²`.
    pub fn read<const N: usize>(
        at: usize,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> Result<Self, FreeJointError> {
        if at.checked_add(7).is_none_or(|end| end > N) {
            return Err(FreeJointError::OutOfRange);
        }
        let e = Quaternion::new(q[at + 3], q[at + 4], q[at + 5], q[at + 6]);
        let rate = Quaternion::new(qd[at + 3], qd[at + 4], qd[at + 5], qd[at + 6]);
        let norm2 = e.norm_squared();
        if !(norm2 > T::zero() && norm2.is_finite()) {
            return Err(FreeJointError::NoAttitude);
        }
        let two = T::one() + T::one();
        let angular = (rate * e.conjugate()).imag() * (two / norm2);
        Ok(FreeMotion {
            position: Vector3::new(q[at], q[at + 1], q[at + 2]),
            orientation: UnitQuaternion::from_quaternion(e),
            linear: Vector3::new(qd[at], qd[at + 1], qd[at + 2]),
            angular,
        })
    }
}
