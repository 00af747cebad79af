use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        parameters: [g],
        mass: diag[1.0, 1.0],
        forces: [0.0, -gravity],
        constraints: [x + y == length],
    }
}

fn main() {}
