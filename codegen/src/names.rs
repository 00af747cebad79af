//! Names shared by every stage: what the DSL reserves and how generated code
//! names what it introduces. The model stage rejects a user name that would
//! collide with one of these; the emission stage produces them.

/// Names the DSL or the generated code already uses.
pub const RESERVED: &[&str] = &[
    "t",
    "dot",
    "dt",
    "q",
    "qd",
    "qdd",
    "T",
    "Self",
    "self",
    "correction",
    "None",
    "Some",
    "Ok",
    "Err",
    "Result",
    "Option",
];

/// The DSL's named constants, with their values.
pub const CONSTANTS: &[(&str, f64)] = &[("PI", std::f64::consts::PI), ("E", std::f64::consts::E)];

/// Generated locals and private items begin with this prefix, which user
/// names may not.
pub const GENERATED_PREFIX: &str = "__";

/// The local name generated code gives the velocity of coordinate `name`.
pub fn velocity_name(name: &str) -> String {
    format!("{name}_dot")
}

/// The local name generated code gives the acceleration of coordinate
/// `name` (in inverse dynamics).
pub fn acceleration_name(name: &str) -> String {
    format!("{name}_ddot")
}
