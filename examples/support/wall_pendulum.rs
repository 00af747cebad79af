//! The pendulum hitting a wall of the example `pendulum_wall` and of
//! `benches/impact.rs`, written once.

use constrained::constrained_system;

constrained_system! {
    /// A bob of mass `m` on a rod of length `l`, a wall at `x = wall`.
    pub struct WallPendulum {
        coordinates: [x, y],
        parameters: [m, l, g, wall],
        mass: diag[m, m],
        forces: [0.0, -m * g],
        constraints: [x.powi(2) + y.powi(2) == l.powi(2)],
        unilateral: [x <= wall],
    }
}
