use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x],
        mass: diag[1.0],
        constraint: [x == 1.0],
    }
}

fn main() {}
