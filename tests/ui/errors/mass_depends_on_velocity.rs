use constrained::constrained_system;

constrained_system! {
    struct Rocket {
        coordinates: [x],
        definitions: [speed = dot(x)],
        mass: diag[1.0 + speed],
    }
}

fn main() {}
