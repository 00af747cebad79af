use constrained::constrained_system;

// Issue 30: constants finite as written that overflow (or are NaN) where
// the generated code evaluates them, spanned where they occur.

constrained_system! {
    // In a constraint: the constraint is spanned.
    pub struct InConstraint {
        coordinates: [x, y],
        mass: diag[1.0, 1.0],
        constraints: [x * PI.powi(1000) == y],
    }
}

constrained_system! {
    // In the mass matrix: `mass` is spanned.
    pub struct InMass {
        coordinates: [x],
        mass: diag[E.powi(710)],
    }
}

constrained_system! {
    // In the forces, NaN: the struct's name.
    pub struct InForces {
        coordinates: [x],
        mass: diag[1.0],
        forces: [2.0.asin() * x],
    }
}

fn main() {}
