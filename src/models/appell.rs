use crate::constrained_system;

constrained_system! {
    /// Appell's particle (Udwadia & Kalaba, eq. 28) with `h = z`: a unit mass
    /// under gravity whose velocity obeys `ẋ² + ẏ² − ż² = 2αh`, a constraint
    /// nonlinear in the velocities. Written divided by 2 so that
    /// `A = [ẋ, ẏ, −ż]` exactly as in eq. 30.
    pub struct Appell {
        coordinates: [x, y, z],
        parameters: [g, alpha],
        mass: diag[1.0, 1.0, 1.0],
        forces: [0.0, 0.0, -g],
        definitions: [h = z],
        constraints: [
            (dot(x).powi(2) + dot(y).powi(2) - dot(z).powi(2)) / 2.0 == alpha * h,
        ],
        eliminate: [x],
    }
}

constrained_system! {
    /// Appell's particle with the time-dependent `h = x·y + sin t`: the
    /// constraint depends explicitly on time, so `b` picks up `α·∂h/∂t`.
    pub struct AppellTimeDependent {
        coordinates: [x, y, z],
        parameters: [g, alpha],
        mass: diag[1.0, 1.0, 1.0],
        forces: [0.0, 0.0, -g],
        definitions: [h = x * y + t.sin()],
        constraints: [
            (dot(x).powi(2) + dot(y).powi(2) - dot(z).powi(2)) / 2.0 == alpha * h,
        ],
    }
}
