//! Numerics beside the expressions: dense linear algebra at compile time
//! (`linalg`), the structural patterns of
//! matrices and their elimination orders (`sparsity`), and the
//! deterministic pseudo-random points at which properties are sampled
//! ([`rng`]).

pub(crate) mod linalg;
pub mod rng;
pub(crate) mod sparsity;
