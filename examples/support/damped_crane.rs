//! The damped crane of the example `crane` and of `tests/stick_slip.rs`,
//! written once.

use constrained::constrained_system;

constrained_system! {
    /// A trolley (`xc`) on a rail with Coulomb friction, a load (`x`, `y`)
    /// on a rod of length `l` from a pivot damped by `c` (a torque
    /// `−c l² θ̇`: the load's velocity relative to the trolley, which is
    /// across the rod, times `c`), a saturated PD drive to `target`. The
    /// rail's normal force is the crane's weight `(mc + ml) g` (the rod's
    /// vertical pull differs from `ml g` by the swing's second order).
    pub struct DampedCrane {
        coordinates: [xc, x, y],
        parameters: [mc, ml, l, g, mu_s, mu_k, kp, kd, umax, target, c],
        mass: diag[mc, ml, ml],
        definitions: [
            drive = clamp(kp * (target - xc) - kd * dot(xc), -umax, umax),
            swing = c * (dot(x) - dot(xc)),
        ],
        forces: [drive + swing, -swing, -ml * g - c * dot(y)],
        constraints: [(x - xc).powi(2) + y.powi(2) == l.powi(2)],
        friction: [coulomb(dot(xc), (mc + ml) * g, mu_s, mu_k)],
    }
}
