//! What `features = ["std"]` promises a user, from the outside:
//! `constrained::nalgebra` has `std` (`DVector`, `from_vec`), `?` carries
//! every runtime error into `Box<dyn Error>`, and the guides' flow calls
//! the system's methods on the state without naming the trait.

use constrained::models::{Appell, SphericalPendulum};
use constrained::nalgebra::{DMatrix, DVector, SVector, Vector3};
use constrained::{DormandPrince45, State};
use std::error::Error;

#[test]
fn nalgebra_through_the_facade_has_std() {
    let v = DVector::from_vec(vec![1.0, 2.0, 3.0]);
    let s = SVector::<f64, 3>::from_vec(vec![1.0, 2.0, 3.0]);
    let m = DMatrix::<f64>::identity(3, 3);
    assert_eq!((&m * &v).as_slice(), s.as_slice());
}

fn simulate() -> Result<f64, Box<dyn Error>> {
    let system = SphericalPendulum::<f64>::new(1.0, 9.81, 0.8);
    let mut state = State::new(0.0, Vector3::new(0.48, 0.0, -0.64), Vector3::new(0.0, 1.9, 0.0));
    DormandPrince45::new(1e-9, 1e-12).advance(&system, &mut state, 1.0)?; // IntegrationError
    let qdd = state.acceleration(&system)?; // DynamicsError
    let gibbs_appell = state.acceleration_gibbs_appell(&system)?; // GibbsAppellError
    Ok((qdd - gibbs_appell).norm())
}

#[test]
fn question_mark_into_box_dyn_error() {
    let difference = simulate().expect("the pendulum integrates");
    assert!(difference < 1e-12, "{difference}");
}

#[test]
fn errors_arrive_boxed_with_their_message() {
    // Appell's particle at rest: A = 0, the Gibbs–Appell form is undefined.
    let appell = Appell::<f64>::new(9.81, 0.5);
    let rest = State::new(0.0, Vector3::new(0.1, 0.2, 0.3), Vector3::zeros());
    let boxed: Box<dyn Error> = rest
        .acceleration_gibbs_appell(&appell)
        .map(|_| ())
        .map_err(Box::new)
        .expect_err("rank deficient at rest");
    assert!(!boxed.to_string().is_empty());
}
