//! `constrained_system!` called from a `macro_rules!` macro, the way a user
//! stamps out a family of systems. A fragment such as `$k:expr` reaches
//! the DSL as an invisible group: it must keep its grouping, so that
//! `$k * x` with `$k = 1.0 + 3.0` is `4 x`, not `1 + 3 x` (the expansion
//! takes the compiler's tokens for such input instead of reading its
//! text). Identifiers passed in (`$name:ident`) name the generated struct.

use constrained::nalgebra::SVector;
use constrained::{constrained_system, ConstrainedSystem, State};

macro_rules! spring {
    ($name:ident, $stiffness:expr) => {
        constrained_system! {
            /// A unit mass on a spring whose stiffness is a fragment.
            pub struct $name {
                coordinates: [x],
                kinetic_energy: dot(x).powi(2) / 2.0,
                potential_energy: $stiffness * x.powi(2) / 2.0,
            }
        }
    };
}

spring!(GroupedSpring, 1.0 + 3.0);
spring!(PlainSpring, 4.0);

constrained_system! {
    /// The same spring written out: `V = 2 x²`.
    pub struct WrittenSpring {
        coordinates: [x],
        kinetic_energy: dot(x).powi(2) / 2.0,
        potential_energy: 2.0 * x.powi(2),
    }
}

/// `ẍ` of each at `x = 0.5`: `−k x = −2` with `k = 4` for all three (a
/// lost grouping gives `V = 1 + 1.5 x²`, `ẍ = −1.5`).
#[test]
fn a_fragment_keeps_its_grouping() {
    let state = State::new(0.0, SVector::<f64, 1>::new(0.5), SVector::zeros());
    let accelerations = [
        ConstrainedSystem::acceleration(&GroupedSpring::new(), &state),
        ConstrainedSystem::acceleration(&PlainSpring::new(), &state),
        ConstrainedSystem::acceleration(&WrittenSpring::new(), &state),
    ];
    for a in accelerations {
        let a = a.expect("a spring's acceleration is finite");
        assert!((a[0] + 2.0).abs() < 1e-15, "ẍ = {}", a[0]);
    }
}
