use crate::constrained_system;

constrained_system! {
    /// A thin disk (a coin) of mass `m` and radius `r` rolling without
    /// slipping on a horizontal plane, in Euler angles, from its energies:
    /// centre `(x, y, r sin θ)`, heading `phi` (rotation about the
    /// vertical), `th` the angle between the symmetry axis
    /// `k = (sin θ sin φ, −sin θ cos φ, cos θ)` and the vertical, spin
    /// `psi`; moments of inertia `a` about a diameter and `c` about the axis.
    /// Angular velocity `ω = φ̇ ẑ + θ̇ n + ψ̇ k` with `n = (cos φ, sin φ, 0)`;
    /// rolling is `v = r ω × u`, `u = k × n` pointing from the contact to
    /// the centre: two nonholonomic constraints (the vertical one is the
    /// height `r sin θ` itself).
    pub struct RollingDisk {
        coordinates: [x, y, th, phi, psi],
        parameters: [m, r, a, c, g],
        definitions: [
            wx = dot(th) * phi.cos() + dot(psi) * th.sin() * phi.sin(),
            wy = dot(th) * phi.sin() - dot(psi) * th.sin() * phi.cos(),
            wz = dot(phi) + dot(psi) * th.cos(),
            ux = -th.cos() * phi.sin(),
            uy = th.cos() * phi.cos(),
            uz = th.sin(),
            spin = wx * th.sin() * phi.sin() - wy * th.sin() * phi.cos() + wz * th.cos(),
        ],
        kinetic_energy: m * (dot(x).powi(2) + dot(y).powi(2) + dt(r * th.sin()).powi(2)) / 2.0
            + (a * (wx.powi(2) + wy.powi(2) + wz.powi(2)) + (c - a) * spin.powi(2)) / 2.0,
        potential_energy: m * g * r * th.sin(),
        constraints: [
            dot(x) == r * (wy * uz - wz * uy),
            dot(y) == r * (wz * ux - wx * uz),
        ],
    }
}
