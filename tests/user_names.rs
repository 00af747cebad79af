//! Names as the user's literature writes them (`WFrad`, `Iwr11`, a
//! coordinate `Xw`, an input `Tw`) compile without a single warning in the
//! user's crate: the generated items allow the naming lints. Warnings are
//! denied in this module, so a lint on generated code fails the build; and
//! the model is checked against its closed form, so it is the model meant.
#![deny(warnings)]

use constrained::constrained_system;
use constrained::nalgebra::Vector2;

constrained_system! {
    /// A wheel of radius `WFrad` and spin inertia `Iwr11` rolling without
    /// slipping down a slope at `Theta`, driven by a torque `Tw`.
    pub struct RollingWheel {
        coordinates: [Xw, Phi],
        parameters: [Mw, WFrad, Iwr11, g, Theta],
        inputs: [Tw],
        kinetic_energy: Mw * dot(Xw).powi(2) / 2.0 + Iwr11 * dot(Phi).powi(2) / 2.0,
        potential_energy: -Mw * g * Xw * Theta.sin(),
        forces: [0.0, Tw],
        constraints: [dot(Xw) == WFrad * dot(Phi)],
    }
}

#[test]
fn literature_names_compile_without_warnings_and_roll_as_the_closed_form() {
    let (mw, wf_rad, iwr11, g, theta, tw) = (2.0, 0.35, 0.09, 9.81, 0.2_f64, 1.5);
    let wheel = RollingWheel::<f64>::new(mw, wf_rad, iwr11, g, theta, tw);
    let (q, qd) = (Vector2::new(0.3, -1.0), Vector2::new(1.4, 4.0));
    let qdd = wheel
        .acceleration(&q, &qd, 0.0)
        .expect("M is positive definite");
    // Rolling: ẍ (Mw + Iwr11/WFrad²) = Mw g sin Θ + Tw/WFrad, φ̈ = ẍ/WFrad.
    let xdd = (mw * g * theta.sin() + tw / wf_rad) / (mw + iwr11 / (wf_rad * wf_rad));
    assert!((qdd[0] - xdd).abs() <= 1e-12 * xdd.abs(), "{qdd} vs {xdd}");
    assert!((qdd[1] - xdd / wf_rad).abs() <= 1e-12 * xdd.abs() / wf_rad);
    assert_eq!(wheel.WFrad, wf_rad);
}
