use crate::constrained_system;

constrained_system! {
    /// A parallelogram four-bar linkage in body coordinates: three uniform
    /// bars in the plane, each with its centre `(xᵢ, yᵢ)` and angle `φᵢ`
    /// (mass `m`, moment of inertia `jm` about the centre), joined by four
    /// pins (8 constraints, 1 degree of freedom): the crank (length `l`)
    /// turns about the origin, the rocker (length `l`) about `(d, 0)`, and
    /// the coupler (length `d`) joins their tips; gravity along −y.
    ///
    /// At `φ₁ = 0` all three bars lie on the x axis: a branch point, where
    /// `A` loses rank and the linkage could switch to its anti-parallelogram
    /// branch. Near it (`φ₁ = θ`, small) `A` has full rank but its smallest
    /// singular value is of order `θ`; [`four_bar_state`] gives the state on
    /// the parallelogram branch, whose motion is known in closed form
    /// ([`four_bar_acceleration`]).
    pub struct ParallelogramFourBar {
        coordinates: [x1, y1, p1, x2, y2, p2, x3, y3, p3],
        parameters: [m, jm, l, d, g],
        mass: diag[m, m, jm, m, m, jm, m, m, jm],
        forces: [0.0, -m * g, 0.0, 0.0, -m * g, 0.0, 0.0, -m * g, 0.0],
        constraints: [
            x1 - l / 2.0 * p1.cos() == 0.0,
            y1 - l / 2.0 * p1.sin() == 0.0,
            x1 + l / 2.0 * p1.cos() == x2 - d / 2.0 * p2.cos(),
            y1 + l / 2.0 * p1.sin() == y2 - d / 2.0 * p2.sin(),
            x3 - l / 2.0 * p3.cos() == d,
            y3 - l / 2.0 * p3.sin() == 0.0,
            x3 + l / 2.0 * p3.cos() == x2 + d / 2.0 * p2.cos(),
            y3 + l / 2.0 * p3.sin() == y2 + d / 2.0 * p2.sin(),
        ],
    }
}

constrained_system! {
    /// The same parallelogram four-bar in its three link angles `φ₁, φ₂, φ₃`
    /// (crank, coupler, rocker), from its energies: a configuration-
    /// dependent, block-diagonal `M(q)` (the coupler's centre moves with
    /// the crank, the rocker's with itself) and 2 loop-closure constraints.
    /// Its accelerations are the angle accelerations of
    /// [`ParallelogramFourBar`] at the same motion; on the parallelogram
    /// branch the state is `φ = (θ, 0, θ)`, `φ̇ = (ω, 0, ω)`.
    pub struct ParallelogramFourBarAngles {
        coordinates: [p1, p2, p3],
        parameters: [m, jm, l, d, g],
        definitions: [
            x1 = l / 2.0 * p1.cos(),
            y1 = l / 2.0 * p1.sin(),
            x2 = l * p1.cos() + d / 2.0 * p2.cos(),
            y2 = l * p1.sin() + d / 2.0 * p2.sin(),
            x3 = d + l / 2.0 * p3.cos(),
            y3 = l / 2.0 * p3.sin(),
        ],
        kinetic_energy: m / 2.0
            * (dt(x1).powi(2) + dt(y1).powi(2) + dt(x2).powi(2) + dt(y2).powi(2)
                + dt(x3).powi(2) + dt(y3).powi(2))
            + jm / 2.0 * (dot(p1).powi(2) + dot(p2).powi(2) + dot(p3).powi(2)),
        potential_energy: m * g * (y1 + y2 + y3),
        constraints: [
            l * p1.cos() + d * p2.cos() == d + l * p3.cos(),
            l * p1.sin() + d * p2.sin() == l * p3.sin(),
        ],
    }
}

/// The state of [`ParallelogramFourBar`] on its parallelogram branch with
/// crank angle `theta` and rate `omega` (`φ₁ = φ₃ = θ`, `φ₂ = 0`): exactly
/// consistent, at position and velocity level.
pub fn four_bar_state<T: nalgebra::RealField + Copy>(
    system: &ParallelogramFourBar<T>,
    theta: T,
    omega: T,
) -> crate::State<T, 9> {
    let (l, d) = (system.l, system.d);
    let half = l / (T::one() + T::one());
    let (s, c) = theta.sin_cos();
    let q = nalgebra::SVector::<T, 9>::from([
        half * c,
        half * s,
        theta,
        l * c + d / (T::one() + T::one()),
        l * s,
        T::zero(),
        d + half * c,
        half * s,
        theta,
    ]);
    let qd = nalgebra::SVector::<T, 9>::from([
        -half * s * omega,
        half * c * omega,
        omega,
        -l * s * omega,
        l * c * omega,
        T::zero(),
        -half * s * omega,
        half * c * omega,
        omega,
    ]);
    crate::State::new(T::zero(), q, qd)
}

/// The exact acceleration at [`four_bar_state`], from the linkage's
/// one-degree-of-freedom Lagrangian: crank and rocker rotate about their
/// pins and the coupler translates, so `T = ½ I θ̇²` with
/// `I = 3/2 m l² + 2 jm` and `V = 2 m g l sin θ`, giving
/// `θ̈ = −2 m g l cos θ / I`; each centre's acceleration follows from its
/// position as a function of `θ`. An oracle independent of the
/// generalized-inverse solve.
pub fn four_bar_acceleration<T: nalgebra::RealField + Copy>(
    system: &ParallelogramFourBar<T>,
    theta: T,
    omega: T,
) -> nalgebra::SVector<T, 9> {
    let (m, jm, l, g) = (system.m, system.jm, system.l, system.g);
    let two = T::one() + T::one();
    let inertia = (two + T::one()) / two * m * l * l + two * jm;
    let alpha = -two * m * g * l * theta.cos() / inertia;
    let (s, c) = theta.sin_cos();
    // d²/dt² of (r cos θ, r sin θ) = r (−s α − c ω², c α − s ω²).
    let ax = -(s * alpha + c * omega * omega);
    let ay = c * alpha - s * omega * omega;
    let half = l / two;
    nalgebra::SVector::<T, 9>::from([
        half * ax,
        half * ay,
        alpha,
        l * ax,
        l * ay,
        T::zero(),
        half * ax,
        half * ay,
        alpha,
    ])
}
