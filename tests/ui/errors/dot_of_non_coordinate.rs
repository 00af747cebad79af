use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        parameters: [g],
        definitions: [h = x * y],
        mass: diag[1.0, 1.0],
        constraints: [dot(x) + dot(g) == 0.0, dot(h) + dot(t) == dot(w)],
    }
}

fn main() {}
