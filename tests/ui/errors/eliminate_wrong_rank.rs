use constrained::constrained_system;

// Rank 2: two coordinates must be eliminated.
constrained_system! {
    struct Pendulum {
        coordinates: [x1, y1, x2, y2],
        mass: diag[1.0, 1.0, 1.0, 1.0],
        constraints: [
            x1.powi(2) + y1.powi(2) == 1.0,
            (x2 - x1).powi(2) + (y2 - y1).powi(2) == 1.0,
        ],
        eliminate: [x1],
    }
}

// Rank 2 on the constraint surface, though the third row is independent
// elsewhere: redundancy is measured where the system can be.
constrained_system! {
    struct Redundant {
        coordinates: [x1, y1, x2, y2],
        mass: diag[1.0, 1.0, 1.0, 1.0],
        definitions: [
            phi1 = x1.powi(2) + y1.powi(2) - 1.0,
            phi2 = (x2 - x1).powi(2) + (y2 - y1).powi(2) - 1.0,
        ],
        constraints: [phi1, phi2, (1.0 + x2.powi(2)) * phi1 + phi2],
        eliminate: [x1, y1, x2],
    }
}

// The columns of x and y are equal: their accelerations cannot both be eliminated.
constrained_system! {
    struct Dependent {
        coordinates: [x, y, z],
        mass: diag[1.0, 1.0, 1.0],
        constraints: [x + y == 1.0, z == 2.0],
        eliminate: [x, y],
    }
}

fn main() {}
