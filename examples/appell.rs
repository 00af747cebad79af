//! Appell's particle (Udwadia & Kalaba, eq. 28–30): a unit mass under gravity
//! whose speed is tied to its height, `ẋ² + ẏ² − ż² = 2αh`, a constraint
//! nonlinear in the velocities that Lagrange's classical equations cannot
//! take. The macro derives `A q̈ = b` at compile time; this example prints the
//! derivation, checks it against the paper's eq. 30 at a state on the
//! constraint, and shows that the residual φ vanishes there.
//!
//! Run with `cargo run --example appell`.

use constrained::models::AppellTimeDependent;
use constrained::nalgebra::Vector3;

fn main() {
    let (g, alpha) = (9.81, 0.5);
    let system = AppellTimeDependent::<f64>::new(g, alpha);
    println!("{}", AppellTimeDependent::<f64>::DERIVATION);

    // A state on the constraint: choose x, y, z, ẋ, ẏ, t and solve for ż.
    let (x, y, z, xd, yd, t) = (0.3, -0.4, 1.0, 1.2, 0.7, 0.25_f64);
    let h = x * y + t.sin();
    let zd = (xd * xd + yd * yd - 2.0 * alpha * h).sqrt();
    let (q, qd) = (Vector3::new(x, y, z), Vector3::new(xd, yd, zd));

    let phi = system.constraint_residual(&q, &qd, t)[0];
    let (a, b) = system.constraint_matrices(&q, &qd, t);
    // Eq. 30 written out by hand: h_x = y, h_y = x, h_z = 0, h_t = cos t.
    let b_eq30 = alpha * (y * xd + x * yd + t.cos());

    println!("State: q = ({x}, {y}, {z}), q̇ = ({xd}, {yd}, {zd:.6}), t = {t}");
    println!("  φ            = {phi:.3e}   (on the constraint)");
    println!("  A            = [{:.6}, {:.6}, {:.6}]", a[0], a[1], a[2]);
    println!(
        "  eq. 30: A    = [ẋ, ẏ, −ż] = [{xd:.6}, {yd:.6}, {:.6}]",
        -zd
    );
    println!("  b            = {:.12}", b[0]);
    println!("  eq. 30: b    = {b_eq30:.12}");
    let agree = (a - Vector3::new(xd, yd, -zd).transpose()).abs().max() == 0.0
        && (b[0] - b_eq30).abs() <= 1e-14 * b_eq30.abs().max(1.0)
        && phi.abs() < 1e-14;
    println!("Derivation agrees with eq. 30: {agree}");
    if !agree {
        std::process::exit(1);
    }
}
