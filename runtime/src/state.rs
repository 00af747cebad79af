use nalgebra::{RealField, SVector};

/// The state of a system with `N` coordinates at time `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<T, const N: usize> {
    /// Time.
    pub t: T,
    /// Coordinates `q`.
    pub q: SVector<T, N>,
    /// Velocities `q̇`.
    pub qd: SVector<T, N>,
}

impl<T: RealField + Copy, const N: usize> State<T, N> {
    /// A state from its parts.
    pub fn new(t: T, q: SVector<T, N>, qd: SVector<T, N>) -> Self {
        State { t, q, qd }
    }

    /// Whether every component (and `t`) is finite.
    pub fn is_finite(&self) -> bool {
        self.t.is_finite()
            && self.q.iter().all(|x| x.is_finite())
            && self.qd.iter().all(|x| x.is_finite())
    }
}
