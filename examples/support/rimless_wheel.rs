//! The rimless wheel of the example `rimless_wheel`, of `tests/impacts.rs`,
//! of `benches/impact.rs` and of the firmware (in `f32`), written once.

use constrained::constrained_system;

constrained_system! {
    /// A rimless wheel in the plane: hub `(x, y)`, rotation `th`, spokes of
    /// length `l` every `a2` radians, the stance spoke (at `th + phase`
    /// from straight down) pinned at `(px, py)`, the slope through the
    /// origin at angle `gamma` downhill towards `+x`. The gap is the next
    /// spoke's height over the slope.
    pub struct RimlessWheel {
        coordinates: [x, y, th],
        parameters: [m, inertia, l, g, a2, gamma, phase, px, py],
        mass: diag[m, m, inertia],
        forces: [0.0, -m * g, 0.0],
        constraints: [
            x + l * (th + phase).sin() == px,
            y - l * (th + phase).cos() == py,
        ],
        unilateral: [
            gamma.sin() * (x + l * (th + phase + a2).sin())
                + gamma.cos() * (y - l * (th + phase + a2).cos()) >= 0.0,
        ],
    }
}
