use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x],
        parameters: [g],
        mass: diag[1.0],
        constraints: [g == 9.81, t.sin(), x - x == 0.0],
    }
}

fn main() {}
