use constrained::constrained_system;

constrained_system! {
    struct Particle {
        coordinates: [x, y],
        parameters: [g],
        inputs: [u],
        mass: diag[1.0, 1.0],
        forces: [u, -g],
        unilateral: [
            y == 0.0,
            y - dot(x) >= 0.0,
            y <= t,
            g >= 1.0,
            x + u >= 0.0,
            y >= zz,
            y,
        ],
    }
}

fn main() {}
