//! Butcher tableaux: the explicit Runge–Kutta methods as data.
//!
//! A method is a [`Tableau`] (stage nodes `c`, stage weights `a`, solution
//! weights `b` and, for an embedded pair, the error weights `e = b − b̂`)
//! named by a marker type that implements [`Method`]. The engine in
//! `explicit.rs` steps every method alike; adding one is a tableau, a marker
//! and a type alias (see [`BogackiShampine`]).

/// The coefficients of an explicit Runge–Kutta method with `S` stages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tableau<const S: usize> {
    /// Stage nodes `cᵢ` (stage `i` is evaluated at `t + cᵢ h`).
    pub c: [f64; S],
    /// Stage weights `aᵢⱼ`, strictly lower triangular.
    pub a: [[f64; S]; S],
    /// Weights `bⱼ` of the propagated solution.
    pub b: [f64; S],
    /// `eⱼ = bⱼ − b̂ⱼ` of an embedded pair (the local error estimate is
    /// `h Σ eⱼ kⱼ`); all zero for a method without one.
    pub e: [f64; S],
    /// Order of the propagated solution.
    pub order: u32,
    /// Order of the embedded solution `b̂` (0 when there is none): the error
    /// estimate is `O(h^(error_order + 1))`, which sets the step-size
    /// controller's exponent.
    pub error_order: u32,
}

impl<const S: usize> Tableau<S> {
    /// First same as last: the last stage is evaluated at the new solution
    /// (`c = 1`, last row of `a` equal to `b`), so it is the next step's
    /// first stage and costs nothing there. Always inlined: on a method's
    /// constant tableau it folds to a constant.
    #[inline(always)]
    pub fn is_fsal(&self) -> bool {
        S > 0 && self.c[S - 1] == 1.0 && self.a[S - 1] == self.b
    }
}

/// A marker type naming an explicit Runge–Kutta method with `S` stages.
pub trait Method<const S: usize> {
    /// Its coefficients.
    const TABLEAU: Tableau<S>;
}

/// A [`Method`] with an embedded error estimate, usable with adaptive steps.
///
/// Its continuous extension (dense output) between `y₀` and `y₁` is
/// Hairer's form,
/// `y(θ) = y₀ + θ (Δ + (1 − θ)(h k₁ − Δ + θ (Δ − h k_S − (h k₁ − Δ) + (1 − θ) h Σ dⱼ kⱼ)))`
/// with `Δ = y₁ − y₀` and `θ = (t − t₀)/h`: with `d = 0` the cubic Hermite
/// interpolant through both ends and their slopes (third order), and with
/// a method's own `d` a higher-order one.
pub trait Embedded<const S: usize>: Method<S> {
    /// The weights `dⱼ` of the continuous extension (zero: cubic Hermite).
    const DENSE: [f64; S] = [0.0; S];
}

/// The classical fourth-order method (Kutta 1901; Hairer, Nørsett & Wanner,
/// *Solving Ordinary Differential Equations I*, Table II.1.2, left).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Classic4;

impl Method<4> for Classic4 {
    const TABLEAU: Tableau<4> = Tableau {
        c: [0.0, 0.5, 0.5, 1.0],
        a: [
            [0.0, 0.0, 0.0, 0.0],
            [0.5, 0.0, 0.0, 0.0],
            [0.0, 0.5, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ],
        b: [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
        e: [0.0; 4],
        order: 4,
        error_order: 0,
    };
}

/// Kutta's 3/8 rule, fourth order (Hairer, Nørsett & Wanner, Table II.1.2,
/// right): the same cost as [`Classic4`], smaller error constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ThreeEighths;

impl Method<4> for ThreeEighths {
    const TABLEAU: Tableau<4> = Tableau {
        c: [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0],
        a: [
            [0.0, 0.0, 0.0, 0.0],
            [1.0 / 3.0, 0.0, 0.0, 0.0],
            [-1.0 / 3.0, 1.0, 0.0, 0.0],
            [1.0, -1.0, 1.0, 0.0],
        ],
        b: [1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0],
        e: [0.0; 4],
        order: 4,
        error_order: 0,
    };
}

/// The Dormand–Prince 5(4) pair: J. R. Dormand and P. J. Prince, "A family
/// of embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6 (1980) 19–26;
/// tableau as in Hairer, Nørsett & Wanner, Table II.5.2. The fifth-order
/// solution propagates (local extrapolation); the seventh stage is the
/// derivative at the new point (first same as last).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DormandPrince;

impl Method<7> for DormandPrince {
    const TABLEAU: Tableau<7> = Tableau {
        c: [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0],
        a: [
            [0.0; 7],
            [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0],
            [
                19372.0 / 6561.0,
                -25360.0 / 2187.0,
                64448.0 / 6561.0,
                -212.0 / 729.0,
                0.0,
                0.0,
                0.0,
            ],
            [
                9017.0 / 3168.0,
                -355.0 / 33.0,
                46732.0 / 5247.0,
                49.0 / 176.0,
                -5103.0 / 18656.0,
                0.0,
                0.0,
            ],
            DORMAND_PRINCE_B,
        ],
        b: DORMAND_PRINCE_B,
        e: [
            71.0 / 57600.0,
            0.0,
            -71.0 / 16695.0,
            71.0 / 1920.0,
            -17253.0 / 339200.0,
            22.0 / 525.0,
            -1.0 / 40.0,
        ],
        order: 5,
        error_order: 4,
    };
}

/// Dormand & Prince's fourth-order continuous extension, as in Hairer's
/// `DOPRI5` (`CONTD5`; Hairer, Nørsett & Wanner, II.6).
impl Embedded<7> for DormandPrince {
    const DENSE: [f64; 7] = [
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ];
}

const DORMAND_PRINCE_B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];

/// The Bogacki–Shampine 3(2) pair: P. Bogacki and L. F. Shampine, "A 3(2)
/// pair of Runge–Kutta formulas", Appl. Math. Lett. 2 (1989) 321–325 (the
/// method of MATLAB's `ode23`). Third order propagated, first same as last:
/// three evaluations per accepted step; for loose tolerances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BogackiShampine;

impl Method<4> for BogackiShampine {
    const TABLEAU: Tableau<4> = Tableau {
        c: [0.0, 0.5, 0.75, 1.0],
        a: [
            [0.0, 0.0, 0.0, 0.0],
            [0.5, 0.0, 0.0, 0.0],
            [0.0, 0.75, 0.0, 0.0],
            [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
        ],
        b: [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
        // b̂ = (7/24, 1/4, 1/3, 1/8).
        e: [
            2.0 / 9.0 - 7.0 / 24.0,
            1.0 / 3.0 - 1.0 / 4.0,
            4.0 / 9.0 - 1.0 / 3.0,
            -1.0 / 8.0,
        ],
        order: 3,
        error_order: 2,
    };
}

impl Embedded<4> for BogackiShampine {}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order conditions up to order 4 (Butcher's rooted trees), and
    /// consistency `cᵢ = Σⱼ aᵢⱼ` of every tableau.
    fn order_conditions<const S: usize>(t: &Tableau<S>, order: u32) -> f64 {
        let (a, b, c) = (&t.a, &t.b, &t.c);
        let sum = |f: &dyn Fn(usize) -> f64| (0..S).map(f).sum::<f64>();
        let ac = |i: usize| sum(&|j| a[i][j] * c[j]);
        let mut worst = (0..S)
            .map(|i| (c[i] - sum(&|j| a[i][j])).abs())
            .fold(0.0, f64::max);
        let mut check = |value: f64, expected: f64| worst = worst.max((value - expected).abs());
        check(sum(&|i| b[i]), 1.0);
        if order >= 2 {
            check(sum(&|i| b[i] * c[i]), 1.0 / 2.0);
        }
        if order >= 3 {
            check(sum(&|i| b[i] * c[i] * c[i]), 1.0 / 3.0);
            check(sum(&|i| b[i] * ac(i)), 1.0 / 6.0);
        }
        if order >= 4 {
            check(sum(&|i| b[i] * c[i].powi(3)), 1.0 / 4.0);
            check(sum(&|i| b[i] * c[i] * ac(i)), 1.0 / 8.0);
            check(sum(&|i| b[i] * sum(&|j| a[i][j] * c[j] * c[j])), 1.0 / 12.0);
            check(sum(&|i| b[i] * sum(&|j| a[i][j] * ac(j))), 1.0 / 24.0);
        }
        worst
    }

    #[test]
    fn tableaux_satisfy_their_order_conditions() {
        assert!(order_conditions(&Classic4::TABLEAU, 4) < 1e-15);
        assert!(order_conditions(&ThreeEighths::TABLEAU, 4) < 1e-15);
        assert!(order_conditions(&DormandPrince::TABLEAU, 4) < 1e-15);
        assert!(order_conditions(&BogackiShampine::TABLEAU, 3) < 1e-15);
        // The embedded solutions b̂ = b − e have their stated orders too.
        let embedded = |t: &Tableau<7>| Tableau {
            b: core::array::from_fn(|i| t.b[i] - t.e[i]),
            ..*t
        };
        assert!(order_conditions(&embedded(&DormandPrince::TABLEAU), 4) < 1e-15);
        let bs = BogackiShampine::TABLEAU;
        let hat = Tableau {
            b: core::array::from_fn(|i| bs.b[i] - bs.e[i]),
            ..bs
        };
        assert!(order_conditions(&hat, 2) < 1e-15);
        // …and not the next one (the estimate measures something).
        assert!(order_conditions(&hat, 3) > 1e-3);
    }

    #[test]
    fn first_same_as_last() {
        assert!(DormandPrince::TABLEAU.is_fsal());
        assert!(BogackiShampine::TABLEAU.is_fsal());
        assert!(!Classic4::TABLEAU.is_fsal());
        assert!(!ThreeEighths::TABLEAU.is_fsal());
    }
}
