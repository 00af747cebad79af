use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        parameters: [x],
        definitions: [y = 2.0],
        mass: diag[1.0, 1.0],
    }
}

fn main() {}
