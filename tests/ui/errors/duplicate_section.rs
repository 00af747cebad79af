use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x],
        mass: diag[1.0],
        mass: diag[2.0],
    }
}

fn main() {}
