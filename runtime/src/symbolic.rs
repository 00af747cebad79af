/// A constrained system as text in sympy syntax, emitted by `constrained_system!`
/// as the associated constant `SYMBOLIC`.
///
/// Every expression is a `&'static str` that `sympy.sympify` reads once the
/// names below are declared as symbols: powers are `**`, velocities are written
/// `dot(q)`, time is `t`, rationals are exact (`1/2`). The DSL's definitions
/// are substituted; subexpressions that recur are named `__s1`, `__s2`, …
/// and listed, in order, in [`definitions`](Self::definitions) (read each
/// with the earlier ones in scope, and substitute). The strings are the macro's own simplified forms, so an
/// independent derivation (see `tests/sympy/`) can compare against them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SymbolicSystem {
    /// Name of the generated struct.
    pub name: &'static str,
    /// Generalised coordinates `q`, in order.
    pub coordinates: &'static [&'static str],
    /// Parameters (struct fields), in order.
    pub parameters: &'static [&'static str],
    /// Control inputs (the struct fields after the parameters), in order;
    /// they appear in `forces` (or the generalized forces) only.
    pub inputs: &'static [&'static str],
    /// Mass matrix `M(q, t)`, row by row (n × n).
    pub mass: &'static [&'static [&'static str]],
    /// Impressed forces `F(q, q̇, t)` (n).
    pub forces: &'static [&'static str],
    /// Constraints `φ(q, q̇, t) = 0` (k), as written (`lhs - rhs` for `lhs == rhs`).
    pub constraints: &'static [&'static str],
    /// `A` of `A q̈ = b`, row by row (k × n).
    pub a_matrix: &'static [&'static [&'static str]],
    /// `b` of `A q̈ = b` (k).
    pub b_vector: &'static [&'static str],
    /// The energies `M` and `F` were derived from (`kinetic_energy`,
    /// `potential_energy`), when given.
    pub energies: Option<SymbolicEnergies>,
    /// Shared subexpressions `(name, expression)`, in order: every other
    /// expression here may use their names, each may use earlier ones.
    pub definitions: &'static [(&'static str, &'static str)],
}

/// `T`, `V` and the generalized forces `Q` of a system given by its
/// energies, in sympy syntax: `M = ∂²T/∂q̇∂q̇ᵀ` and
/// `F = Q − ∂V/∂q + ∂T/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t` were derived from them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SymbolicEnergies {
    /// `T(q, q̇, t)`, or `None` when `M` was given directly.
    pub kinetic: Option<&'static str>,
    /// `V(q, t)` (`"0"` when not given).
    pub potential: &'static str,
    /// `Q` (n), as written in `forces`.
    pub generalized_forces: &'static [&'static str],
}

/// The gaps of a system with `unilateral: [..]`, in sympy syntax (as
/// [`SymbolicSystem`]'s expressions, with the DSL's definitions substituted
/// and no shared names): emitted by `constrained_system!` as the associated
/// constant `SYMBOLIC_GAPS`, only for a system with gaps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SymbolicGaps {
    /// The gaps `g(q) ≥ 0` (u), in the order written (`rhs - lhs` for
    /// `lhs <= rhs`, `lhs - rhs` for `lhs >= rhs`).
    pub gaps: &'static [&'static str],
    /// Their gradients `∂g/∂q`, row by row (u × n): the rows the impact map
    /// adds to the constraints'.
    pub gap_jacobian: &'static [&'static [&'static str]],
}
