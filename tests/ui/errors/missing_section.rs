use constrained::constrained_system;

constrained_system! {
    struct Particle {
        forces: [1.0],
    }
}

fn main() {}
