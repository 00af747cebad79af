/// How a constraint `φ(q, q̇, t) = 0` is turned into a row of `A q̈ = b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConstraintLevel {
    /// φ has no velocity (holonomic): differentiated twice.
    Position,
    /// φ contains some `q̇`: differentiated once.
    Velocity,
}
