//! Balancing a cart-pole with an LQR designed from the generated
//! linearization, in both forms of the model:
//!
//! - generalized coordinates (`CartPole`: `s`, `θ`, from its energies):
//!   `linearize` at the upright state gives `(A, B)` for `x = (s, θ, ṡ, θ̇)`;
//! - Cartesian coordinates with the rod as a constraint
//!   (`CartPoleCartesian`: `s`, `x`, `y`): `linearize_reduced` gives the
//!   linear model on the constraint manifold, in the coordinates the rod
//!   leaves free (its full linearization carries the rod's direction and
//!   is not stabilizable).
//!
//! Both are discretized for a 10 ms zero-order hold and given the gain of
//! the discrete-time LQR (`constrained::control`), then run from a pole
//! 0.3 rad off upright: the push is set every 10 ms, and RK4 holds it over
//! the step.
//!
//! `cargo run --release --example cart_pole_lqr [-- --duration 6]`

#[path = "support/mod.rs"]
mod support;

use constrained::control::{discretize, lqr_gain};
use constrained::models::{CartPole, CartPoleCartesian};
use constrained::nalgebra::{Matrix1, Matrix4, SVector, Vector2, Vector3};
use constrained::{Rk4, Stabilization, State};
use support::{plot, Options, Panel, Series};

const MC: f64 = 1.0;
const MP: f64 = 0.3;
const L: f64 = 0.8;
const G: f64 = 9.81;
/// The control period (zero-order hold).
const PERIOD: f64 = 0.01;
/// The initial offset of the pole from upright.
const OFFSET: f64 = 0.3;

/// LQR weights: the pole angle and the cart position matter most.
fn weights() -> (Matrix4<f64>, Matrix1<f64>) {
    (
        Matrix4::from_diagonal(&constrained::nalgebra::Vector4::new(1.0, 10.0, 0.1, 0.1)),
        Matrix1::new(0.1),
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(6.0);
    let (q_weight, r_weight) = weights();
    let rk4 = Rk4::new(PERIOD / 4.0);

    // Generalized coordinates: x = (s, θ, ṡ, θ̇), upright at θ = π.
    let mut generalized = CartPole::new(MC, MP, L, G, 0.0);
    let upright = Vector2::new(0.0, std::f64::consts::PI);
    let (a, b) = generalized.linearize(&upright, &Vector2::zeros(), 0.0)?;
    let (ad, bd) = discretize(&a, &b, PERIOD)?;
    let k = lqr_gain(&ad, &bd, &q_weight, &r_weight, 1e-12, 10_000)?;
    let row = |k: &constrained::nalgebra::SMatrix<f64, 1, 4>| {
        k.iter()
            .map(|x| format!("{x:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!("generalized form (state s, θ − π, ṡ, θ̇): K = [{}]", row(&k));
    let mut state = State::new(
        0.0,
        Vector2::new(0.0, std::f64::consts::PI + OFFSET),
        Vector2::zeros(),
    );
    let mut angle_generalized = Vec::new();
    let mut push_generalized = Vec::new();
    while state.t < options.duration {
        let x = SVector::<f64, 4>::new(
            state.q[0],
            state.q[1] - upright[1],
            state.qd[0],
            state.qd[1],
        );
        generalized.push = -(k * x)[0];
        angle_generalized.push((state.t, state.q[1] - upright[1]));
        push_generalized.push((state.t, generalized.push));
        let t_end = state.t + PERIOD;
        rk4.advance(&generalized, &mut state, t_end)?;
    }
    let final_generalized = state;

    // Cartesian coordinates: the reduced linear model at the upright state.
    let mut cartesian = CartPoleCartesian::new(MC, MP, L, G, 0.0);
    let up = Vector3::new(0.0, 0.0, L);
    let reduced = cartesian.linearize_reduced(&up, &Vector3::zeros(), 0.0)?;
    let (ad, bd) = discretize(&reduced.a, &reduced.b, PERIOD)?;
    // The reduced state is (s, x, ṡ, ẋ); near upright θ − π ≈ (s − x)/l,
    // so z = (s, θ − π, ṡ, θ̇) ≈ P x: the same cost is Pᵀ Q P, and the gain
    // should come out as K P if the two linear models are the same physics.
    assert_eq!(
        (reduced.coordinates, reduced.speeds),
        ([0, 1], [0, 1]),
        "the rod leaves s and x free at upright"
    );
    let p = Matrix4::new(
        1.0,
        0.0,
        0.0,
        0.0, //
        1.0 / L,
        -1.0 / L,
        0.0,
        0.0, //
        0.0,
        0.0,
        1.0,
        0.0, //
        0.0,
        0.0,
        1.0 / L,
        -1.0 / L,
    );
    let q_cartesian = p.transpose() * q_weight * p;
    let k_cartesian = lqr_gain(&ad, &bd, &q_cartesian, &r_weight, 1e-12, 10_000)?;
    println!(
        "Cartesian form (reduced state s, x, ṡ, ẋ): K = [{}]",
        row(&k_cartesian)
    );
    println!(
        "largest difference from the generalized gain mapped by P: {:.1e}",
        (k_cartesian - k * p).amax()
    );
    let theta = OFFSET;
    let mut state = State::new(
        0.0,
        Vector3::new(0.0, -L * theta.sin(), L * theta.cos()),
        Vector3::zeros(),
    );
    let rk4_projected = rk4.with_stabilization(Stabilization::projection(1e-12));
    let mut angle_cartesian = Vec::new();
    let mut push_cartesian = Vec::new();
    while state.t < options.duration {
        let x = SVector::<f64, 4>::new(state.q[0], state.q[1], state.qd[0], state.qd[1]);
        cartesian.push = -(k_cartesian * x)[0];
        // The angle from upright, for comparison: θ − π = atan2(s − x, y).
        let angle = (state.q[0] - state.q[1]).atan2(state.q[2]);
        angle_cartesian.push((state.t, angle));
        push_cartesian.push((state.t, cartesian.push));
        let t_end = state.t + PERIOD;
        rk4_projected.advance(&cartesian, &mut state, t_end)?;
    }
    let final_angle = (state.q[0] - state.q[1]).atan2(state.q[2]);
    println!(
        "after {:.0} s: generalized |θ − π| = {:.2e} rad, |s| = {:.2e} m; \
         Cartesian |θ − π| = {:.2e} rad, |s| = {:.2e} m",
        options.duration,
        (final_generalized.q[1] - std::f64::consts::PI).abs(),
        final_generalized.q[0].abs(),
        final_angle.abs(),
        state.q[0].abs(),
    );
    let difference = angle_generalized
        .iter()
        .zip(&angle_cartesian)
        .fold(0.0f64, |m, (a, b)| m.max((a.1 - b.1).abs()));
    println!("largest difference of the two forms' angles: {difference:.2e} rad");
    // The example checks itself (the test command runs it): the two linear
    // models are one, and the pole is up after the default run.
    let gain_difference = (k_cartesian - k * p).amax();
    if gain_difference > 1e-8 {
        return Err(format!("the two forms' gains differ by {gain_difference:e}").into());
    }
    if options.duration >= 5.0 && (final_angle.abs() > 1e-2 || difference > 1e-2) {
        return Err(format!(
            "not balanced: final angle {final_angle:e}, forms apart {difference:e}"
        )
        .into());
    }

    let out = options.plot_path("cart_pole_lqr");
    plot(
        &out,
        "Cart-pole balanced by an LQR from the generated linearization",
        &[
            Panel::new(
                "pole angle from upright",
                "t [s]",
                "θ − π [rad]",
                vec![
                    Series::new("generalized (s, θ)", angle_generalized),
                    Series::new("Cartesian (s, x, y), reduced", angle_cartesian),
                ],
            ),
            Panel::new(
                "push on the cart",
                "t [s]",
                "u [N]",
                vec![
                    Series::new("generalized (s, θ)", push_generalized),
                    Series::new("Cartesian (s, x, y), reduced", push_cartesian),
                ],
            ),
        ],
    )?;
    println!("plot: {}", out.display());
    Ok(())
}
