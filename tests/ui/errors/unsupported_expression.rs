use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        mass: diag[1.0, 1.0],
        forces: [x.foo(), x % y],
        constraints: [x.powi(1.5) == y.sin(2.0), (x == y) == 1.0, x == 1u8, [x] == y],
    }
}

fn main() {}
