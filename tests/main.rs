//! The integration tests of `constrained`, one binary with a module per
//! file (each file's own docs say what it checks). One binary because the
//! reference models are generic: every test binary used to compile and link
//! its own instances of the generated code, and their link steps dominated
//! the build. A new test file is added here as a module. `no_allocation`
//! stays a binary of its own (a counting global allocator, no harness), as
//! do the compile-fail tests (`tests/ui`, a package of their own).

#[macro_use]
mod common;

mod appell_eq30;
mod appell_eq32;
mod auxiliary;
mod bodies;
mod body_jacobians;
mod centroidal;
mod contacts;
mod dense_output;
mod directional;
mod dispatch;
mod docs;
mod energies;
mod evaluations;
mod event_edges;
mod events;
mod fault_matrix;
mod finite_differences;
mod floating;
mod frames;
mod free_base;
mod gauss;
mod generated_multipliers;
mod gibbs_appell;
mod held;
mod hostile_runtime;
mod impacts;
mod integrators;
mod invocation;
mod jacobian_edges;
mod joints;
mod linearize;
mod lock_rank;

mod momentum;
mod multiplier_jacobian;
mod nonsmooth;
mod projection;
mod quadruped;
mod rank_decisions;
mod reduced_tangent;
mod rigid_body;
mod robustness;
mod rotations;
mod slid_frames;
mod spherical;
mod stick_slip;
mod urdf_as_written;
mod user_names;
mod velocity_jacobians;
