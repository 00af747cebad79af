use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, t, sin, x_dot],
        parameters: [dot, __hidden, q],
        mass: diag[1.0, 1.0, 1.0, 1.0],
    }
}

fn main() {}
