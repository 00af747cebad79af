//! Rotations of bodies in constraints: an orientation lock
//! (`orientation(a) == [roll, pitch, yaw]`) welding a free body to the
//! world, its multipliers the torque that balances gravity's moment; and a
//! disc written with bodies rolling on the ground
//! (`velocity(disc, position(tilt, [0, 0, 0]))`, the disc's material point
//! at the contact), the same motion as the rolling disk of
//! `constrained::models` written with coordinates; `angular_velocity` is
//! the disc's `ω` in closed form.

use constrained::floating::FreeMotion;
use constrained::models::RollingDisk;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{SVector, UnitQuaternion, Vector3};
use constrained::{constrained_system, ConstrainedSystem, State};

constrained_system! {
    /// A block on a free joint welded to the world: its origin held at the
    /// world's and its axes at `Rz(yaw) Ry(pitch) Rx(roll)`.
    pub struct Welded {
        parameters: [roll, pitch, yaw],
        bodies: [
            block {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 2.0,
                com: [0.1, 0.05, -0.2],
                inertia: diag[0.01, 0.02, 0.03],
            },
        ],
        constraints: [
            position(block, [0.0, 0.0, 0.0]) == [0.0, 0.0, 0.0],
            orientation(block) == [roll, pitch, yaw],
        ],
    }
}

/// A body welded to the world by a point and an orientation lock stays at
/// rest (`q̈ = 0` to 1e-12), the point's `λ` is the force `(0, 0, m g)`
/// and the lock's `λ` the torque `−(R c) × m g⃗` that balances gravity's
/// moment about the point (world axes, 1e-12 of `m g |c|`), at several
/// attitudes; the lock's three rows are independent of the point's and of
/// the quaternion's norm (no redundancy).
#[test]
fn an_orientation_lock_gives_the_torque_that_balances_gravity() {
    let (m, g) = (2.0, 9.81);
    let com = Vector3::new(0.1, 0.05, -0.2);
    let mut worst: f64 = 0.0;
    for (roll, pitch, yaw) in [(0.0, 0.0, 0.0), (0.3, -0.2, 0.5), (-1.1, 0.7, 2.9)] {
        let block = Welded::new(roll, pitch, yaw);
        let attitude = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        let base = FreeMotion::at_rest(Vector3::zeros(), attitude);
        let (mut q, mut qd) = (SVector::<f64, 7>::zeros(), SVector::<f64, 7>::zeros());
        base.write(0, &mut q, &mut qd).unwrap();
        let s = State::new(0.0, q, qd);
        assert!(ConstrainedSystem::constraint_residual(&block, &s).amax() < 1e-15);
        let (qdd, lambda) = block.acceleration_and_multipliers(&s).unwrap();
        let force = Vector3::new(lambda[0], lambda[1], lambda[2]);
        let torque = Vector3::new(lambda[3], lambda[4], lambda[5]);
        let weight = Vector3::new(0.0, 0.0, -m * g);
        let expected_torque = -(attitude * com).cross(&weight);
        let scale = m * g * com.norm();
        worst = worst
            .max(qdd.amax())
            .max((force + weight).amax() / (m * g))
            .max((torque - expected_torque).amax() / scale);
        println!(
            "weld at ({roll}, {pitch}, {yaw}): torque {torque:?}, expected {expected_torque:?}"
        );
    }
    assert!(worst < 1e-12, "{worst:e}");
    assert_eq!(<Welded<f64> as ConstrainedSystem<f64, 7, 7>>::REDUNDANCY, 0);
}

constrained_system! {
    /// The rolling disk of `constrained::models` written with bodies: a
    /// carriage moving in `x` and `y` carries the contact point, turns by
    /// the heading `phi` about the vertical and tilts by `th` about the
    /// heading's `x`; the disc spins by `psi` about its axis, its centre `r`
    /// up the tilted `y`. Rolling: the disc's material point at the
    /// contact (the tilted frame's origin) has no horizontal velocity.
    pub struct DiskBodies {
        parameters: [m, r, a, c, g],
        gravity: [0.0, 0.0, -g],
        bodies: [
            carriage_x { joint: prismatic(x, [1.0, 0.0, 0.0]) },
            carriage_y { parent: carriage_x, joint: prismatic(y, [0.0, 1.0, 0.0]) },
            heading { parent: carriage_y, joint: revolute(phi, [0.0, 0.0, 1.0]) },
            tilt { parent: heading, joint: revolute(th, [1.0, 0.0, 0.0]) },
            disc {
                parent: tilt,
                joint: revolute(psi, [0.0, 0.0, 1.0]),
                xyz: [0.0, r, 0.0],
                mass: m,
                inertia: diag[a, a, c],
            },
        ],
        constraints: [
            velocity(disc, position(tilt, [0.0, 0.0, 0.0])).x == 0.0,
            velocity(disc, position(tilt, [0.0, 0.0, 0.0])).y == 0.0,
        ],
    }
}

constrained_system! {
    /// The same bodies with the disc's angular velocity held at zero: its
    /// velocity residual is `ω` itself.
    pub struct DiskSpin {
        parameters: [r],
        bodies: [
            carriage_x { joint: prismatic(x, [1.0, 0.0, 0.0]) },
            carriage_y { parent: carriage_x, joint: prismatic(y, [0.0, 1.0, 0.0]) },
            heading { parent: carriage_y, joint: revolute(phi, [0.0, 0.0, 1.0]) },
            tilt { parent: heading, joint: revolute(th, [1.0, 0.0, 0.0]) },
            disc {
                parent: tilt,
                joint: revolute(psi, [0.0, 0.0, 1.0]),
                xyz: [0.0, r, 0.0],
                mass: 1.0,
                inertia: diag[0.1, 0.1, 0.2],
            },
        ],
        constraints: [angular_velocity(disc) == [0.0, 0.0, 0.0]],
    }
}

/// The disc with bodies and the disk with coordinates, at the same states:
/// the carriage's `x = x_c + r cos θ sin φ`, `y = y_c − r cos θ cos φ`
/// (the contact from the centre), their second derivatives by the chain
/// rule; `q̈` agree to 1e-12 (relative to the largest entry), and
/// `angular_velocity(disc)` is `φ̇ ẑ + θ̇ n + ψ̇ k` to 1e-14.
#[test]
fn a_disc_written_with_bodies_rolls_as_the_disk_written_with_coordinates() {
    let (m, r, a, c, g) = (1.0, 0.5, 0.06, 0.12, 9.81);
    let coin = RollingDisk::new(m, r, a, c, g);
    let bodies = DiskBodies::new(m, r, a, c, g);
    let spin = DiskSpin::new(r);
    let (mut worst, mut omega): (f64, f64) = (0.0, 0.0);
    for k in 0..30 {
        let x = f64::from(k);
        let (th, phi, psi) = (0.9 + 0.4 * x.sin(), 0.7 * x, 0.3 * x.cos());
        let (dth, dphi, dpsi) = (0.8 * x.cos(), 1.5 - 0.1 * x, 4.0 * (0.5 * x).sin() + 2.0);
        let (st, ct, sp, cp) = (th.sin(), th.cos(), phi.sin(), phi.cos());
        // The coordinate disk's rolling rows give the centre's velocity.
        let w = Vector3::new(
            dth * cp + dpsi * st * sp,
            dth * sp - dpsi * st * cp,
            dphi + dpsi * ct,
        );
        let u = Vector3::new(-ct * sp, ct * cp, st);
        let v = (w * r).cross(&u);
        let (xc, yc) = (0.2 * x, -0.1 * x);
        let sc = State::new(
            0.0,
            SVector::from([xc, yc, th, phi, psi]),
            SVector::from([v.x, v.y, dth, dphi, dpsi]),
        );
        assert!(ConstrainedSystem::constraint_velocity_residual(&coin, &sc).amax() < 1e-14);
        // The carriage: the contact point, centre − r u.
        let (dxc, dyc) = (v.x, v.y);
        let xdot = dxc + r * (-st * sp * dth + ct * cp * dphi);
        let ydot = dyc + r * (st * cp * dth + ct * sp * dphi);
        let sb = State::new(
            0.0,
            SVector::from([xc + r * ct * sp, yc - r * ct * cp, phi, th, psi]),
            SVector::from([xdot, ydot, dphi, dth, dpsi]),
        );
        let qc = ConstrainedSystem::acceleration(&coin, &sc).unwrap();
        let qb = ConstrainedSystem::acceleration(&bodies, &sb).unwrap();
        let (ddth, ddphi) = (qc[2], qc[3]);
        // f = r cos θ sin φ, h = −r cos θ cos φ: f̈ = f_θ θ̈ + f_φ φ̈ + f_θθ θ̇² + 2 f_θφ θ̇ φ̇ + f_φφ φ̇².
        let fdd = -r * st * sp * ddth + r * ct * cp * ddphi
            - r * ct * sp * dth * dth
            - 2.0 * r * st * cp * dth * dphi
            - r * ct * sp * dphi * dphi;
        let hdd = r * st * cp * ddth + r * ct * sp * ddphi + r * ct * cp * dth * dth
            - 2.0 * r * st * sp * dth * dphi
            + r * ct * cp * dphi * dphi;
        let mapped = SVector::<f64, 5>::from([qc[0] + fdd, qc[1] + hdd, ddphi, ddth, qc[4]]);
        worst = worst.max((qb - mapped).amax() / mapped.amax());
        let w_bodies = ConstrainedSystem::constraint_velocity_residual(&spin, &sb);
        omega =
            omega.max((Vector3::new(w_bodies[0], w_bodies[1], w_bodies[2]) - w).amax() / w.amax());
    }
    println!("rolling disc, bodies vs coordinates: q̈ {worst:.1e}, ω {omega:.1e}");
    assert!(worst < 1e-12 && omega < 1e-14, "{worst:e} {omega:e}");
}

constrained_system! {
    /// A free base with a two-link arm and a third link, the arm's last
    /// link held at an attitude of the world and the third link at the
    /// attitude of the arm's first: orientation locks of both kinds, over
    /// a quaternion and revolute joints with turned frames.
    pub struct LockedChain {
        parameters: [roll, pitch, yaw],
        bodies: [
            base {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 3.0,
                com: [0.02, -0.01, 0.05],
                inertia: diag[0.05, 0.07, 0.09],
            },
            upper {
                parent: base,
                joint: revolute(a1, [0.0, 1.0, 0.0]),
                xyz: [0.1, 0.0, -0.2],
                rpy: [0.2, 0.0, 0.1],
                mass: 1.0,
                com: [0.0, 0.0, -0.15],
                inertia: diag[0.01, 0.01, 0.002],
            },
            lower {
                parent: upper,
                joint: revolute(a2, [1.0, 0.0, 0.0]),
                xyz: [0.0, 0.05, -0.3],
                mass: 0.5,
                com: [0.0, 0.0, -0.1],
                inertia: diag[0.004, 0.004, 0.001],
            },
            other {
                parent: base,
                joint: revolute(a3, [0.0, 0.0, 1.0]),
                xyz: [0.2, 0.1, 0.0],
                rpy: [0.0, -0.4, 0.0],
                mass: 0.4,
                com: [0.05, 0.0, 0.0],
                inertia: diag[0.001, 0.002, 0.002],
            },
        ],
        constraints: [
            orientation(lower) == [roll, pitch, yaw],
            orientation(other) == orientation(upper),
        ],
    }
}

/// The locks' rows of `A` and `b`, which the macro builds in closed form
/// from the bodies' angular velocities (`φ̇ = B(E) ωₐ − B(Eᵀ) ω_b`), are
/// the derivatives of the rows `φ` themselves: `A = ∂φ/∂q` against central
/// differences of `constraint_residual`, `A q̇ = φ̇` (the velocity
/// residual) to rounding, and `b = −(∂φ̇/∂q) q̇` against central
/// differences of `constraint_velocity_residual` along `q̇`, at states off
/// the constraint and with the quaternion off the unit sphere (where
/// `R(q/|q|)` still turns the base); 1e-7 of each quantity's largest entry.
#[test]
fn the_locks_rows_are_the_derivatives_of_the_locks() {
    const N: usize = 10;
    let lock = LockedChain::new(0.3, -0.2, 0.5);
    let mut worst: [f64; 3] = [0.0; 3];
    for k in 0..8 {
        let x = f64::from(k);
        let q = SVector::<f64, N>::from_fn(|i, _| {
            let i = i as f64;
            0.7 * (1.3 * i + 0.9 * x).sin() + if i == 3.0 { 1.1 } else { 0.0 }
        });
        let qd = SVector::<f64, N>::from_fn(|i, _| 1.5 * (0.8 * i as f64 - 0.6 * x).cos());
        let (a, b) = lock.constraint_matrices(&q, &qd, 0.0);
        let phi = |q: &SVector<f64, N>| lock.constraint_residual(q, &qd, 0.0);
        let rate = |q: &SVector<f64, N>| lock.constraint_velocity_residual(q, &qd, 0.0);
        let h = 1e-6;
        let mut by_differences = a * 0.0;
        for j in 0..N {
            let mut step = SVector::<f64, N>::zeros();
            step[j] = h;
            by_differences.set_column(j, &((phi(&(q + step)) - phi(&(q - step))) / (2.0 * h)));
        }
        let along = (rate(&(q + qd * h)) - rate(&(q - qd * h))) / (2.0 * h);
        worst[0] = worst[0].max((a - by_differences).amax() / a.amax());
        worst[1] = worst[1].max((a * qd - rate(&q)).amax() / rate(&q).amax());
        worst[2] = worst[2].max((b + along).amax() / b.amax());
    }
    println!("A {:e}, A q̇ {:e}, b {:e}", worst[0], worst[1], worst[2]);
    assert!(worst[0] < 1e-7 && worst[2] < 1e-7, "{worst:?}");
    assert!(worst[1] < 1e-13, "{worst:?}");
}
