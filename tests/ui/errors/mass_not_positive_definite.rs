use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        mass: [[1.0, 2.0], [2.0, 1.0]],
    }
}

fn main() {}
