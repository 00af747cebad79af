use constrained::constrained_system;

constrained_system! {
    // Both `mass` and `kinetic_energy`.
    pub struct Both {
        coordinates: [x],
        mass: diag[1.0],
        kinetic_energy: dot(x).powi(2) / 2.0,
    }
}

constrained_system! {
    // T cubic in a velocity.
    pub struct Cubic {
        coordinates: [x],
        kinetic_energy: dot(x).powi(3),
    }
}

constrained_system! {
    // V with a velocity, directly and through `dt` of a position.
    pub struct VelocityInV {
        coordinates: [x, y],
        kinetic_energy: (dot(x).powi(2) + dot(y).powi(2)) / 2.0,
        potential_energy: x * dot(y) + dt(x.powi(2)),
    }
}

constrained_system! {
    // `dt` of a velocity-dependent expression would need accelerations.
    pub struct DtOfVelocity {
        coordinates: [x],
        kinetic_energy: dot(x).powi(2) / 2.0,
        potential_energy: dt(dot(x)),
    }
}

fn main() {}
