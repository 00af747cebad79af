use crate::constrained_system;
use crate::nalgebra::{RealField, Vector4};
use crate::State;

constrained_system! {
    /// A spherical pendulum in Cartesian coordinates: a point mass `m` on a
    /// massless rod of length `l` pivoting at the origin, gravity along −z.
    pub struct SphericalPendulum {
        coordinates: [x, y, z],
        parameters: [m, g, l],
        mass: diag[m, m, m],
        forces: [0.0, 0.0, -m * g],
        constraints: [x.powi(2) + y.powi(2) + z.powi(2) == l.powi(2)],
    }
}

constrained_system! {
    /// A planar double pendulum in Cartesian coordinates: point masses `m1`,
    /// `m2` on rods `l1` (pivot to mass 1) and `l2` (mass 1 to mass 2),
    /// gravity along −y.
    pub struct DoublePendulum {
        coordinates: [x1, y1, x2, y2],
        parameters: [m1, m2, l1, l2, g],
        mass: diag[m1, m1, m2, m2],
        forces: [0.0, -m1 * g, 0.0, -m2 * g],
        constraints: [
            x1.powi(2) + y1.powi(2) == l1.powi(2),
            (x2 - x1).powi(2) + (y2 - y1).powi(2) == l2.powi(2),
        ],
    }
}

constrained_system! {
    /// The double pendulum with a redundant third constraint
    /// `φ₃ = (1 + x₂²) φ₁ + φ₂`: its row of `A` depends on the other
    /// two only on the constraint surface, so rank decisions need a tolerance.
    pub struct RedundantDoublePendulum {
        coordinates: [x1, y1, x2, y2],
        parameters: [m1, m2, l1, l2, g],
        mass: diag[m1, m1, m2, m2],
        forces: [0.0, -m1 * g, 0.0, -m2 * g],
        definitions: [
            phi1 = x1.powi(2) + y1.powi(2) - l1.powi(2),
            phi2 = (x2 - x1).powi(2) + (y2 - y1).powi(2) - l2.powi(2),
        ],
        constraints: [phi1, phi2, (1.0 + x2.powi(2)) * phi1 + phi2],
    }
}

/// A consistent state of a planar double pendulum with rods `l1`, `l2` from
/// the absolute angles of the rods (from the downward vertical) and their
/// rates: `q = (x₁, y₁, x₂, y₂)` on both constraints, `q̇` tangent to them.
/// Serves [`DoublePendulum`] and [`RedundantDoublePendulum`] alike.
pub fn double_pendulum_state<T: RealField + Copy>(
    l1: T,
    l2: T,
    t: T,
    [t1, t2]: [T; 2],
    [w1, w2]: [T; 2],
) -> State<T, 4> {
    let (s1, c1, s2, c2) = (t1.sin(), t1.cos(), t2.sin(), t2.cos());
    State::new(
        t,
        Vector4::new(l1 * s1, -l1 * c1, l1 * s1 + l2 * s2, -l1 * c1 - l2 * c2),
        Vector4::new(
            l1 * c1 * w1,
            l1 * s1 * w1,
            l1 * c1 * w1 + l2 * c2 * w2,
            l1 * s1 * w1 + l2 * s2 * w2,
        ),
    )
}

impl<T: RealField + Copy> DoublePendulum<T> {
    /// A consistent state from the rods' absolute angles and their rates
    /// (see [`double_pendulum_state`]).
    pub fn state_from_angles(&self, t: T, angles: [T; 2], rates: [T; 2]) -> State<T, 4> {
        double_pendulum_state(self.l1, self.l2, t, angles, rates)
    }
}

impl<T: RealField + Copy> RedundantDoublePendulum<T> {
    /// A consistent state from the rods' absolute angles and their rates
    /// (see [`double_pendulum_state`]).
    pub fn state_from_angles(&self, t: T, angles: [T; 2], rates: [T; 2]) -> State<T, 4> {
        double_pendulum_state(self.l1, self.l2, t, angles, rates)
    }
}
