use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x],
        mass: diag[1.0],
        forces: [1.0 / (2.0 - 2.0)],
    }
}

fn main() {}
