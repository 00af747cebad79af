use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y, z],
        mass: diag[1.0, 1.0],
        forces: [0.0, 0.0, 0.0, 1.0],
    }
}

constrained_system! {
    struct Full {
        coordinates: [x, y],
        mass: [[1.0, 0.0], [0.0]],
    }
}

fn main() {}
