use constrained::constrained_system;

// `^` is Rust's xor, not a power: a hint naming `powi`, spanned on `^` and
// the exponent (`m * x^2` parses as `(m * x) ^ 2`, so the base is not
// repeated in the message).
constrained_system! {
    struct Pendulum {
        coordinates: [x, y],
        parameters: [l, m],
        mass: diag[m, m],
        forces: [0.0, -m * y^2],
        constraints: [x.powi(2) + y.powi(2) == l^m],
    }
}

fn main() {}
