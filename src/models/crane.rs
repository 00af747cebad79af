use crate::constrained_system;

constrained_system! {
    /// An overhead crane: a trolley of mass `mc` at `xc` on a horizontal
    /// rail, and a load of mass `ml` at `(x, y)` hanging from it on a rod of
    /// length `l`, gravity along −y.
    ///
    /// The trolley is driven towards `target` by a saturated PD actuator,
    /// `clamp(kp (target − xc) − kd ẋc, −umax, umax)`, and slowed by Coulomb
    /// friction `μ (mc + ml) g signum(ẋc)` (the rail carries both weights;
    /// `signum(0) = 0`, so a trolley at rest feels none). The non-smooth
    /// functions sit in `forces`, which are never differentiated.
    pub struct Crane {
        coordinates: [xc, x, y],
        parameters: [mc, ml, l, g, mu, kp, kd, umax, target],
        mass: diag[mc, ml, ml],
        definitions: [
            drive = clamp(kp * (target - xc) - kd * dot(xc), -umax, umax),
            friction = mu * (mc + ml) * g * signum(dot(xc)),
        ],
        forces: [drive - friction, 0.0, -ml * g],
        constraints: [(x - xc).powi(2) + y.powi(2) == l.powi(2)],
    }
}
