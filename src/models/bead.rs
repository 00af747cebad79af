use crate::constrained_system;

constrained_system! {
    /// A bead of mass `m` on a circular hoop of radius `r` centred at the
    /// origin, the hoop spinning about the vertical z axis at the constant
    /// rate `omega`, gravity along −z. The hoop's plane contains the z axis
    /// and the direction `(cos ωt, sin ωt, 0)`, so the second constraint
    /// depends explicitly on time.
    pub struct BeadOnRotatingHoop {
        coordinates: [x, y, z],
        parameters: [m, g, r, omega],
        mass: diag[m, m, m],
        forces: [0.0, 0.0, -m * g],
        constraints: [
            x.powi(2) + y.powi(2) + z.powi(2) == r.powi(2),
            x * (omega * t).sin() - y * (omega * t).cos() == 0.0,
        ],
    }
}
