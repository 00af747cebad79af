use constrained::constrained_system;

constrained_system! {
    struct Block {
        coordinates: [x, y],
        parameters: [m, g, mu],
        inputs: [u],
        mass: diag[m, m],
        forces: [u, -m * g],
        constraints: [y == 0.0],
        friction: [
            dot(x) == 0.0,
            coulomb(dot(x), m * g),
            coulomb(x, m * g, mu),
            coulomb(dot(x) * dot(x), m * g, mu),
            coulomb(dot(x) + u, m * g, mu),
            coulomb(dot(x), m * g, mu * x, mu),
            coulomb(dot(x), m * g, mu, t),
            friction(dot(x), m * g, mu),
            coulomb(dot(x), m * g, mu, zz),
        ],
    }
}

fn main() {}
