//! How `gauss` solves Gauss's principle, decided once in stage 3 from what
//! it built: one value of [`Strategy`]. `emit::mass_inverse` carries it out
//! without deciding again, and the derivation states it in the same words
//! ([`Strategy::describe`]), so that `DERIVATION` says what `acceleration`
//! computes.
//!
//! A new strategy is a variant here, its rule in [`Equations::strategy`],
//! its sentence in `describe`, its solver in `emit/mass_inverse/`, and its
//! account in the derivation (`emit/derivation_saddle.rs`).

use super::mass_inverse::{Factored, MassInverse};
use super::Equations;

/// How `gauss` solves `M q̈ = F + Aᵀλ`, `A q̈ = b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// `M⁻¹` as expressions (`M` diagonal or a numeric constant): the
    /// range-space form with `S = A M⁻¹ Aᵀ` written out.
    Symbolic,
    /// `M(q)` factored on its compile-time pattern, then the range-space
    /// form `S = A M⁻¹ Aᵀ`.
    RangeSpace,
    /// A positive semi-definite `M` through its auxiliary mass
    /// `M + s A_RᵀA_R`, then the range-space form.
    Auxiliary,
    /// The saddle-point system `[M Aᵀ; A 0]`, factored once.
    Saddle,
    /// The saddle-point system in the quaternions' velocity coordinates.
    VelocitySaddle,
    /// The velocity form of a floating base on legs, leg by leg.
    Legs,
}

impl Strategy {
    /// Every strategy, for the test that each is stated as it is emitted.
    pub const ALL: [Strategy; 6] = [
        Strategy::Symbolic,
        Strategy::RangeSpace,
        Strategy::Auxiliary,
        Strategy::Saddle,
        Strategy::VelocitySaddle,
        Strategy::Legs,
    ];

    /// The solve in one sentence: the generated `gauss`'s doc and the
    /// derivation both print it.
    pub fn describe(self) -> &'static str {
        match self {
            Strategy::Symbolic => {
                "solve: M⁻¹ known in closed form; with rows, S = A M⁻¹ Aᵀ and r = b − A M⁻¹ F as expressions."
            }
            Strategy::RangeSpace => {
                "solve: M factored as L D Lᵀ on its pattern; with rows, S = A M⁻¹ Aᵀ factored (range-space form)."
            }
            Strategy::Auxiliary => {
                "solve: the auxiliary mass M + s A_RᵀA_R factored as L D Lᵀ, then S = A M⁻¹ Aᵀ factored (range-space form)."
            }
            Strategy::Saddle => "solve: the saddle-point system [M Aᵀ; A 0] factored once as L D Lᵀ.",
            Strategy::VelocitySaddle => {
                "solve: in the quaternions' velocity coordinates, the saddle-point system factored once."
            }
            Strategy::Legs => {
                "solve: in the quaternions' velocity coordinates, each leg through its foot's rows and \
                 the base's inertia with the feet held factored once."
            }
        }
    }
}

impl Equations {
    /// The strategy of `gauss`: the one place it is decided.
    pub fn strategy(&self) -> Strategy {
        match &self.mass_inverse {
            MassInverse::Symbolic(_) => Strategy::Symbolic,
            MassInverse::Factored(f) => self.factored_strategy(f).unwrap_or(Strategy::RangeSpace),
            MassInverse::Auxiliary(f) => self.factored_strategy(f).unwrap_or(Strategy::Auxiliary),
        }
    }

    /// A factored `M`'s saddle-point strategies, which need every row they
    /// solve independent (the range-space form's rank-revealing
    /// factorization answers otherwise); the velocity form replaces the
    /// saddle where there is one, and solves a body held at three or more
    /// points through its own six rows (`super::held`), so that it needs
    /// the rank of `A` to be the rows it keeps.
    fn factored_strategy(&self, f: &Factored) -> Option<Strategy> {
        let full = self.partition.rank == self.a.len();
        if let Some(v) = &f.velocity {
            let kept = v.rows.len() + v.system.quaternions.len();
            if self.partition.rank != kept {
                return None;
            }
            return Some(match &f.legs {
                Some(_) => Strategy::Legs,
                None => Strategy::VelocitySaddle,
            });
        }
        f.saddle.as_ref().filter(|_| full).map(|_| Strategy::Saddle)
    }
}
