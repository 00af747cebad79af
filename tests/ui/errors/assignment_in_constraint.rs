use constrained::constrained_system;

// `=` where a constraint needs `==`: a hint, spanned on the `=`.
constrained_system! {
    struct Pendulum {
        coordinates: [x, y],
        parameters: [l],
        mass: diag[1.0, 1.0],
        constraints: [x.powi(2) + y.powi(2) = l.powi(2)],
    }
}

fn main() {}
