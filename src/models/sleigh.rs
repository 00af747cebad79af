use crate::constrained_system;

constrained_system! {
    /// The Chaplygin sleigh: a rigid body on a plane, `(x, y)` its centre of
    /// mass and `theta` its heading, resting on a knife edge a distance `a`
    /// behind the centre of mass. The blade cannot slide sideways: the
    /// velocity of the contact point `(x − a cos θ, y − a sin θ)` along the
    /// blade's normal `(−sin θ, cos θ)` vanishes, a nonholonomic constraint
    /// linear in the velocities (`a = 0` is the classical knife edge).
    /// `torque` turns it about the vertical: a control input, which
    /// `linearize_reduced` differentiates by (the sympy suite checks it
    /// against `sympy.physics.mechanics.KanesMethod.linearize`).
    pub struct ChaplyginSleigh {
        coordinates: [x, y, theta],
        parameters: [m, inertia, a],
        inputs: [torque],
        mass: diag[m, m, inertia],
        forces: [0.0, 0.0, torque],
        constraints: [-dot(x) * theta.sin() + dot(y) * theta.cos() - a * dot(theta)],
    }
}
