use crate::constrained_system;

constrained_system! {
    /// A slider-crank in Cartesian coordinates: the crank pin `(x1, y1)` (mass
    /// `m1`) turns on a circle of radius `r` about the origin, a rod of length
    /// `l` joins it to the slider `(x2, y2)` (mass `m2`) that runs along the
    /// x axis against a spring of stiffness `k`; gravity along −y. The slider
    /// is held to its guide twice, by `y2 = 0` and by `y2·(1 + x2²) = 0`: on
    /// the guide the two rows of `A` are parallel, off it they are not — the
    /// redundancy that needs a rank tolerance.
    pub struct SliderCrank {
        coordinates: [x1, y1, x2, y2],
        parameters: [m1, m2, r, l, k, g],
        mass: diag[m1, m1, m2, m2],
        forces: [0.0, -m1 * g, -k * x2, -m2 * g],
        constraints: [
            x1.powi(2) + y1.powi(2) == r.powi(2),
            (x2 - x1).powi(2) + (y2 - y1).powi(2) == l.powi(2),
            y2 == 0.0,
            y2 * (1.0 + x2.powi(2)) == 0.0,
        ],
    }
}
