use constrained::constrained_system;

constrained_system! {
    struct Arm {
        coordinates: [a, b],
        mass: [[2.0, a.cos()], [b.cos(), 1.0]],
    }
}

fn main() {}
