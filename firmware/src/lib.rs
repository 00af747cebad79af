//! The simulation the firmware runs, `no_std` and in `f32`, shared by the
//! bare-metal binary and its host run so that both execute the same code.

#![no_std]

use constrained::models::{Appell, DoublePendulum};
// nalgebra's functions (libm) rather than f32's inherent ones: available
// without std, and the same code on the host and the target.
use constrained::nalgebra::{ComplexField, Vector3, Vector4};
use constrained::{Rk4, Stabilization, State};

/// Simulated time, s.
pub const DURATION: f32 = 5.0;
/// RK4 step, s.
pub const STEP: f32 = 1e-3;

/// The final states of both simulations and the largest constraint residual
/// seen along each.
pub struct Report {
    /// Appell's particle at `DURATION`.
    pub appell: State<f32, 3>,
    /// Largest |φ| of Appell's particle.
    pub appell_residual: f32,
    /// The double pendulum at `DURATION`.
    pub pendulum: State<f32, 4>,
    /// Largest |φ| of the double pendulum.
    pub pendulum_residual: f32,
}

/// Appell's particle (g = 9.81, α = 0.5, h = z) from a state on its
/// constraint, and a double pendulum (Baumgarte-stabilized), each `DURATION`
/// seconds of RK4 with step `STEP`.
pub fn simulate() -> Result<Report, constrained::IntegrationError<f32>> {
    let appell_system = Appell::<f32>::new(9.81, 0.5);
    let (xd, yd, z) = (1.2f32, 0.7f32, 1.0f32);
    // ẋ² + ẏ² − ż² = 2αz fixes ż.
    let zd = ComplexField::sqrt(xd * xd + yd * yd - 2.0 * 0.5 * z);
    let mut appell = State::new(0.0, Vector3::new(0.3, -0.4, z), Vector3::new(xd, yd, zd));
    let mut appell_residual = 0.0f32;
    Rk4::new(STEP).advance_with(&appell_system, &mut appell, DURATION, |s| {
        let phi = appell_system.constraint_residual(&s.q, &s.qd, s.t)[0].abs();
        appell_residual = appell_residual.max(phi);
    })?;

    let (l1, l2) = (1.0f32, 0.7f32);
    let pendulum_system = DoublePendulum::<f32>::new(1.0, 0.5, l1, l2, 9.81);
    let (t1, t2) = (1.2f32, -0.4f32);
    let (s1, c1) = (ComplexField::sin(t1), ComplexField::cos(t1));
    let (s2, c2) = (ComplexField::sin(t2), ComplexField::cos(t2));
    let mut pendulum = State::new(
        0.0,
        Vector4::new(l1 * s1, -l1 * c1, l1 * s1 + l2 * s2, -l1 * c1 - l2 * c2),
        Vector4::zeros(),
    );
    let mut pendulum_residual = 0.0f32;
    Rk4::new(STEP)
        .with_stabilization(Stabilization::baumgarte(20.0))
        .advance_with(&pendulum_system, &mut pendulum, DURATION, |s| {
            let phi = pendulum_system.constraint_residual(&s.q, &s.qd, s.t).amax();
            pendulum_residual = pendulum_residual.max(phi);
        })?;
    Ok(Report {
        appell,
        appell_residual,
        pendulum,
        pendulum_residual,
    })
}

/// Writes the report as `name value value …` lines, values in `{:e}` (the
/// shortest form that reads back to the same f32).
pub fn write_report(out: &mut impl core::fmt::Write, report: &Report) -> core::fmt::Result {
    let mut line = |name: &str, values: &[f32]| -> core::fmt::Result {
        write!(out, "{name}")?;
        for v in values {
            write!(out, " {v:e}")?;
        }
        writeln!(out)
    };
    line("appell_t", &[report.appell.t])?;
    line("appell_q", report.appell.q.as_slice())?;
    line("appell_qd", report.appell.qd.as_slice())?;
    line("appell_max_residual", &[report.appell_residual])?;
    line("pendulum_t", &[report.pendulum.t])?;
    line("pendulum_q", report.pendulum.q.as_slice())?;
    line("pendulum_qd", report.pendulum.qd.as_slice())?;
    line("pendulum_max_residual", &[report.pendulum_residual])
}
