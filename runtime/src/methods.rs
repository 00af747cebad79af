//! The one list of the [`ConstrainedSystem`](crate::ConstrainedSystem)
//! methods that forward a generated inherent method: from it follow their
//! declarations in the hidden `Generated` trait (taking `(q, q̇, t)`), in
//! `ConstrainedSystem` (taking a [`State`](crate::State), with these docs),
//! and the blanket impl between the two. A new such method is one row here
//! (and one row of the generator's `FORWARDS` table, which emits the
//! forwarding impl for every system).
//!
//! A row reads
//!
//! ```text
//! /// docs
//! required #[other attributes] fn name(q, qd, t) -> TraitType,
//!     generated GeneratedType, finish function;
//! ```
//!
//! `required` methods every system has; `optional` ones only some (an
//! energy, the bodies' gravity): their `Generated` method returns an
//! `Option` and defaults to `None`. The arguments are a subset of `q`,
//! `qd`, `t`, in that order. `finish` names a function of `system.rs`
//! from the generated value to the trait's (a finiteness check, or
//! `same`). Methods computed from another (`acceleration` from `gauss`)
//! are written by hand beside the table's.

/// Calls `$callback! { .. }` with every row of the table.
macro_rules! forwarded_methods {
    ($callback:ident) => {
        $callback! {
            /// `M(q, t)`.
            required fn mass_matrix(q, t) -> SMatrix<T, N, N>,
                generated SMatrix<T, N, N>, finish same;
            /// `F(q, q̇, t)`.
            required fn forces(q, qd, t) -> SVector<T, N>,
                generated SVector<T, N>, finish same;
            /// `φ(q, q̇, t)`.
            required fn constraint_residual(q, qd, t) -> SVector<T, K>,
                generated SVector<T, K>, finish same;
            /// The constraints at velocity level: `φ̇` for position-level
            /// rows, `φ` for velocity-level ones. Its Jacobian in `q̇` is `A`.
            required fn constraint_velocity_residual(q, qd, t) -> SVector<T, K>,
                generated SVector<T, K>, finish same;
            /// `(A, b)` of `A q̈ = b`.
            required fn constraint_matrices(q, qd, t) -> (SMatrix<T, K, N>, SVector<T, K>),
                generated (SMatrix<T, K, N>, SVector<T, K>), finish same;
            /// The explicit Gibbs–Appell system `(S, s)`, `S q̈ = s` (eq. 18 / 37).
            required #[allow(clippy::type_complexity)] fn gibbs_appell_matrices(q, qd, t)
                -> Result<(SMatrix<T, N, N>, SVector<T, N>), GibbsAppellError>,
                generated Result<(SMatrix<T, N, N>, SVector<T, N>), GibbsAppellError>,
                finish same;
            /// `q̈` from the Gibbs–Appell system; equal to
            /// [`acceleration`](crate::ConstrainedSystem::acceleration) wherever both are defined. An
            /// `Ok` satisfies every row of `A q̈ = b` to `√ε` (relative), not only
            /// the `r` rows of its partition: off the surface of a redundant model,
            /// where a redundant row is independent, it is
            /// `Err(GibbsAppellError::Inconsistent)`.
            required fn acceleration_gibbs_appell(q, qd, t) -> Result<SVector<T, N>, GibbsAppellError>,
                generated Result<SVector<T, N>, GibbsAppellError>, finish finite_gibbs_appell;
            /// The kinetic energy `T(q, q̇, t)`, for a system given by
            /// `kinetic_energy`, by bodies, or by `mass` with
            /// `potential_energy` (`½ q̇ᵀ M q̇`); `None` for one given by
            /// `mass` alone. `Err(NonFinite)` where the value is not finite.
            optional fn kinetic_energy(q, qd, t) -> Option<Result<T, DynamicsError>>,
                generated Option<Result<T, DynamicsError>>, finish finite_scalar;
            /// The potential energy `V(q, t)` (gravity's for bodies, and
            /// `potential_energy` as written), where
            /// [`kinetic_energy`](Self::kinetic_energy) is `Some`.
            optional fn potential_energy(q, t) -> Option<Result<T, DynamicsError>>,
                generated Option<Result<T, DynamicsError>>, finish finite_scalar;
            /// The total energy `T + V`, where
            /// [`kinetic_energy`](Self::kinetic_energy) is `Some`: conserved
            /// where no other force acts, so a generic check of an
            /// integrator's drift.
            optional fn energy(q, qd, t) -> Option<Result<T, DynamicsError>>,
                generated Option<Result<T, DynamicsError>>, finish finite_scalar;
            /// The generalized gravity `g(q)` of a system given by bodies, the
            /// gradient of the bodies' gravitational potential (`None` for
            /// other systems). `Err(NonFinite)` where a value is not finite.
            optional fn gravity_forces(q, t) -> Option<Result<SVector<T, N>, DynamicsError>>,
                generated Option<Result<SVector<T, N>, DynamicsError>>, finish finite_vector;
        }
    };
}

/// The type of a forwarded argument in the `Generated` trait.
macro_rules! argument_type {
    (q) => { &SVector<T, N> };
    (qd) => { &SVector<T, N> };
    (t) => { T };
}

/// The forwarded argument, taken from the state `$s`.
macro_rules! state_argument {
    ($s:ident, q) => {
        &$s.q
    };
    ($s:ident, qd) => {
        &$s.qd
    };
    ($s:ident, t) => {
        $s.t
    };
}

/// The rows' methods of the hidden `Generated` trait (in its body).
macro_rules! generated_declarations {
    ($(
        $(#[doc = $doc:expr])*
        $kind:ident $(#[$attr:meta])* fn $name:ident($($arg:ident),*) -> $ret:ty,
            generated $gen:ty, finish $finish:ident;
    )*) => {$(
        generated_declaration!($kind $(#[doc = $doc])* $(#[$attr])* fn $name($($arg),*) -> $gen);
    )*};
}

/// One method of `Generated`: required, or `None` by default.
macro_rules! generated_declaration {
    (required $(#[$attr:meta])* fn $name:ident($($arg:ident),*) -> $gen:ty) => {
        $(#[$attr])*
        fn $name(&self, $($arg: argument_type!($arg)),*) -> $gen;
    };
    (optional $(#[$attr:meta])* fn $name:ident($($arg:ident),*) -> $gen:ty) => {
        $(#[$attr])*
        #[allow(unused_variables)]
        fn $name(&self, $($arg: argument_type!($arg)),*) -> $gen {
            None
        }
    };
}

/// The rows' methods of `ConstrainedSystem` (in its body).
macro_rules! system_declarations {
    ($(
        $(#[doc = $doc:expr])*
        $kind:ident $(#[$attr:meta])* fn $name:ident($($arg:ident),*) -> $ret:ty,
            generated $gen:ty, finish $finish:ident;
    )*) => {$(
        system_declaration!($kind $(#[doc = $doc])* $(#[$attr])* fn $name -> $ret);
    )*};
}

/// One method of `ConstrainedSystem`: required, or `None` by default (so
/// that a type implementing the trait by hand need not provide it).
macro_rules! system_declaration {
    (required $(#[$attr:meta])* fn $name:ident -> $ret:ty) => {
        $(#[$attr])*
        fn $name(&self, state: &State<T, N>) -> $ret;
    };
    (optional $(#[$attr:meta])* fn $name:ident -> $ret:ty) => {
        $(#[$attr])*
        #[allow(unused_variables)]
        fn $name(&self, state: &State<T, N>) -> $ret {
            None
        }
    };
}

/// The rows' methods of the blanket impl of `ConstrainedSystem` for every
/// `Generated` type (in its body), without the docs (the trait's, whose
/// links to `Self::..` would not resolve in the blanket impl).
macro_rules! system_definitions {
    ($(
        $(#[doc = $doc:expr])*
        $kind:ident $(#[$attr:meta])* fn $name:ident($($arg:ident),*) -> $ret:ty,
            generated $gen:ty, finish $finish:ident;
    )*) => {$(
        $(#[$attr])*
        #[inline]
        fn $name(&self, state: &State<T, N>) -> $ret {
            $finish(Generated::$name(self, $(state_argument!(state, $arg)),*))
        }
    )*};
}
