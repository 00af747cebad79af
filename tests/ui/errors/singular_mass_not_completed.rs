use constrained::constrained_system;

constrained_system! {
    // A rigid body in quaternions without the unit-norm constraint: M = 4GᵀJG
    // has rank 3, and nothing fixes the fourth direction.
    pub struct QuaternionWithoutNorm {
        coordinates: [e0, e1, e2, e3],
        definitions: [
            w1 = 2.0 * (-e1 * dot(e0) + e0 * dot(e1) + e3 * dot(e2) - e2 * dot(e3)),
            w2 = 2.0 * (-e2 * dot(e0) - e3 * dot(e1) + e0 * dot(e2) + e1 * dot(e3)),
            w3 = 2.0 * (-e3 * dot(e0) + e2 * dot(e1) - e1 * dot(e2) + e0 * dot(e3)),
        ],
        kinetic_energy: (w1.powi(2) + 2.0 * w2.powi(2) + 3.0 * w3.powi(2)) / 2.0,
    }
}

constrained_system! {
    // y is massless and the constraint does not involve it.
    pub struct MasslessAndFree {
        coordinates: [x, y],
        mass: diag[1.0, 0.0],
        constraints: [x == 1.0],
    }
}

fn main() {}
