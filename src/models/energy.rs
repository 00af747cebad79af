use crate::constrained_system;

constrained_system! {
    /// A cart-pole in generalized coordinates, from its energies: a cart of
    /// mass `mc` at `s` on a rail, pushed by `push`, and a pole of length
    /// `l` with a point mass `mp` at its tip, at angle `th` from hanging
    /// down. Positions are written once; `dt` gives the velocities, and
    /// Lagrange's equations the non-diagonal `M(q)` and the `θ̇²` term.
    /// `push` is a control input: `acceleration_jacobian` and `linearize`
    /// differentiate by it (`examples/cart_pole_lqr.rs` balances the pole).
    pub struct CartPole {
        coordinates: [s, th],
        parameters: [mc, mp, l, g],
        inputs: [push],
        definitions: [xp = s + l * th.sin(), yp = -l * th.cos()],
        kinetic_energy: mc * dot(s).powi(2) / 2.0
            + mp * (dt(xp).powi(2) + dt(yp).powi(2)) / 2.0,
        potential_energy: mp * g * yp,
        forces: [push, 0.0],
    }
}

constrained_system! {
    /// The same cart-pole in Cartesian coordinates: the cart at `s`, the
    /// pole's tip at `(x, y)`, the rod a position constraint. Linearized in
    /// all three coordinates (six states) it carries the rod's direction; reduced to the
    /// constraint manifold (`constrained::linearize::reduced`) it has the
    /// eigenvalues of [`CartPole`]. `eliminate: [y]` makes the tip's
    /// height the Gibbs–Appell form's dependent coordinate, well defined
    /// near the upright state (the default choice, `x`, is not: `∂φ/∂x = 0`
    /// there).
    pub struct CartPoleCartesian {
        coordinates: [s, x, y],
        parameters: [mc, mp, l, g],
        inputs: [push],
        mass: diag[mc, mp, mp],
        forces: [push, 0.0, -mp * g],
        constraints: [(x - s).powi(2) + y.powi(2) == l.powi(2)],
        eliminate: [y],
    }
}

constrained_system! {
    /// The planar double pendulum in its two absolute angles, from its
    /// energies: the same motion as [`DoublePendulum`](super::DoublePendulum)
    /// in Cartesian coordinates with two rod constraints.
    pub struct DoublePendulumAngles {
        coordinates: [th1, th2],
        parameters: [m1, m2, l1, l2, g],
        definitions: [
            x1 = l1 * th1.sin(),
            y1 = -l1 * th1.cos(),
            x2 = x1 + l2 * th2.sin(),
            y2 = y1 - l2 * th2.cos(),
        ],
        kinetic_energy: m1 * (dt(x1).powi(2) + dt(y1).powi(2)) / 2.0
            + m2 * (dt(x2).powi(2) + dt(y2).powi(2)) / 2.0,
        potential_energy: g * (m1 * y1 + m2 * y2),
    }
}
