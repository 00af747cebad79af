use constrained::constrained_system;

constrained_system! {
    // Position level: differentiated twice, and abs′′ is an impulse.
    pub struct KinkInPosition {
        coordinates: [x, y],
        mass: diag[1.0, 1.0],
        constraints: [x.abs() + y == 1.0],
    }
}

constrained_system! {
    // Velocity level: differentiated once, and signum′ is an impulse.
    pub struct JumpInVelocity {
        coordinates: [x, y],
        mass: diag[1.0, 1.0],
        constraints: [dot(x) == signum(dot(y))],
    }
}

constrained_system! {
    // `E` is the constant e.
    pub struct YoungsModulus {
        coordinates: [x],
        parameters: [E],
        mass: diag[1.0],
        forces: [-E * x],
    }
}

fn main() {}
