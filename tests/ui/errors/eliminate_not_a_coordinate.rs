use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        parameters: [g],
        mass: diag[1.0, 1.0],
        constraints: [dot(x) == dot(y)],
        eliminate: [g, x, x],
    }
}

fn main() {}
