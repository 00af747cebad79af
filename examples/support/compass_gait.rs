//! The compass-gait walker of the example `compass_gait` and of
//! `benches/impact.rs`, written once.

use constrained::constrained_system;

constrained_system! {
    /// The hip at `(x, y)`, the legs at absolute angles `th1`, `th2` from
    /// straight down, the leg masses `b` below the hip (`a` above the
    /// foot); `s = 0` pins leg 1's foot at `(px, py)`, `s = 1` leg 2's.
    /// The slope passes through the origin at angle `gamma`, downhill
    /// towards `+x`.
    pub struct CompassGait {
        coordinates: [x, y, th1, th2],
        parameters: [mh, m, a, b, g, gamma, s, px, py],
        definitions: [
            ll = a + b,
            x1 = x + b * th1.sin(),
            y1 = y - b * th1.cos(),
            x2 = x + b * th2.sin(),
            y2 = y - b * th2.cos(),
        ],
        kinetic_energy: mh * (dot(x).powi(2) + dot(y).powi(2)) / 2.0
            + m * (dt(x1).powi(2) + dt(y1).powi(2) + dt(x2).powi(2) + dt(y2).powi(2)) / 2.0,
        potential_energy: g * (mh * y + m * y1 + m * y2),
        constraints: [
            x + ll * ((1.0 - s) * th1.sin() + s * th2.sin()) == px,
            y - ll * ((1.0 - s) * th1.cos() + s * th2.cos()) == py,
        ],
        unilateral: [
            gamma.sin() * (x + ll * (s * th1.sin() + (1.0 - s) * th2.sin()))
                + gamma.cos() * (y - ll * (s * th1.cos() + (1.0 - s) * th2.cos())) >= 0.0,
        ],
    }
}
