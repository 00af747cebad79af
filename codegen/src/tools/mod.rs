//! What serves tests and benchmarks rather than the macro: the operation
//! counter of generated code ([`op_count`]) and the DSL text of the
//! benchmark models ([`fixtures`]).

#[doc(hidden)] // DSL text for the chains crate and the benches, not API
pub mod fixtures;
pub mod op_count;
