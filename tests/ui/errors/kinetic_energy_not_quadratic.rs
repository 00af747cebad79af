use constrained::constrained_system;

// Issue 30: kinetic energies that look quadratic where a sampling check
// would draw the velocities (positive, below 1), rejected on the
// expression itself.

constrained_system! {
    // |ẋ|·ẋ/2 + ẋ²: `M = 3` by sampling; Lagrange's equations give q̈ = −1.
    pub struct AbsTimesVelocity {
        coordinates: [x],
        kinetic_energy: dot(x).abs() * dot(x) / 2.0 + dot(x).powi(2),
        potential_energy: x.powi(2) / 2.0,
    }
}

constrained_system! {
    pub struct ClampedVelocity {
        coordinates: [x],
        kinetic_energy: dot(x).clamp(-1.0, 1.0).powi(2),
    }
}

constrained_system! {
    // √(ẋ²) = |ẋ|.
    pub struct RootOfSquare {
        coordinates: [x],
        kinetic_energy: dot(x).powi(2).sqrt(),
    }
}

constrained_system! {
    // Zero wherever x < 5.
    pub struct QuarticBeyondFive {
        coordinates: [x],
        kinetic_energy: (x - 5.0).max(0.0) * dot(x).powi(4) + dot(x).powi(2) / 2.0,
    }
}

constrained_system! {
    // Below any sampling tolerance.
    pub struct TinyQuartic {
        coordinates: [x],
        kinetic_energy: 1e-12 * dot(x).powi(4) + dot(x).powi(2) / 2.0,
    }
}

fn main() {}
