use constrained::constrained_system;

constrained_system! {
    /// One input with several independent mistakes: all are reported.
    pub struct Many {
        coordinates: [x, y],
        parameters: [g],
        mass: diag[1.0, dot(y), 3.0],
        forces: [0.0, -mass_of_earth * g],
        constraints: [dot(g) == 0.0, g == 1.0],
    }
}

fn main() {}
