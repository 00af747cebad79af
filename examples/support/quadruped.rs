//! A quadruped with Solo-12's structure, described here from published
//! figures (Grimminger et al., "An Open Torque-Controlled Modular Robot
//! Architecture for Legged Locomotion Research", RA-L 2020: legs of two
//! 0.16 m segments, hips 0.39 m × 0.175 m apart, about 2.5 kg in all; the
//! masses and inertias below are rounded figures of that design, not a copy
//! of any file). A floating base (`free`), three joints per leg — hip
//! abduction `haa` about x, hip and knee flexion `hfe`, `kfe` about y — with
//! a motor torque each, and the four feet fixed on the ground at
//! `(·_x, ·_y, 0)` (three rows each) plus the base quaternion's norm:
//! `K = 13` rows on `N = 19` coordinates. Included by the examples
//! `quadruped` and `quadruped_balance` (whose controller's twin adds the
//! frames it reads, `support/balance.rs`) and the tests of
//! `tests/quadruped.rs` (which add the twin with a fifth, dependent row).

/// The coordinates: the base's position and quaternion, then each leg's
/// `haa, hfe, kfe` in the order front-left, front-right, hind-left,
/// hind-right.
pub const N: usize = 19;
/// The hip positions in the base's frame, and the lateral offset of the
/// foot from the hip (the offsets of the hip flexion, knee and foot).
pub const HIPS: [[f64; 2]; 4] = [
    [0.1946, 0.0875],
    [0.1946, -0.0875],
    [-0.1946, 0.0875],
    [-0.1946, -0.0875],
];
/// Lateral offset from the hip to the foot: `0.014 + 0.037 + 0.008`.
pub const FOOT_OFFSET: f64 = 0.059;
/// Each segment's length.
pub const SEGMENT: f64 = 0.16;
/// The total mass.
pub const MASS: f64 = 1.16 + 4.0 * (0.149 + 0.149 + 0.031);

/// The quadruped's `constrained_system!` as `$name`, with `$extra` rows
/// after the four feet's and, optionally, a `frames` section (the balance
/// controller's kinematics, which the other users need not expand): the
/// model is written once for the examples and for the tests' twin with a
/// dependent fifth row.
macro_rules! quadruped_system {
    ($(#[$attr:meta])* $name:ident, [$($extra:tt)*] $(, frames: [$($frame:tt)*])?) => {
constrained::constrained_system! {
    $(#[$attr])*
    pub struct $name {
        parameters: [fl_x, fl_y, fr_x, fr_y, hl_x, hl_y, hr_x, hr_y],
        inputs: [t_fl_haa, t_fl_hfe, t_fl_kfe, t_fr_haa, t_fr_hfe, t_fr_kfe, t_hl_haa, t_hl_hfe, t_hl_kfe, t_hr_haa, t_hr_hfe, t_hr_kfe],
        bodies: [
            base {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 1.16,
                inertia: diag[0.0058, 0.0194, 0.0246],
            },
            fl_hip {
                parent: base,
                joint: revolute(fl_haa, [1.0, 0.0, 0.0]),
                xyz: [0.1946, 0.0875, 0.0],
                mass: 0.149,
                com: [0.0, 0.014, 0.0],
                inertia: diag[4.0e-5, 7.0e-5, 4.0e-5],
            },
            fl_upper {
                parent: fl_hip,
                joint: revolute(fl_hfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, 0.014, 0.0],
                mass: 0.149,
                com: [0.0, 0.016, -0.078],
                inertia: diag[4.2e-4, 4.1e-4, 2.4e-5],
            },
            fl_lower {
                parent: fl_upper,
                joint: revolute(fl_kfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, 0.037, -0.16],
                mass: 0.031,
                com: [0.0, 0.007, -0.079],
                inertia: diag[1.2e-4, 1.2e-4, 2.1e-6],
            },
            fr_hip {
                parent: base,
                joint: revolute(fr_haa, [1.0, 0.0, 0.0]),
                xyz: [0.1946, -0.0875, 0.0],
                mass: 0.149,
                com: [0.0, -0.014, 0.0],
                inertia: diag[4.0e-5, 7.0e-5, 4.0e-5],
            },
            fr_upper {
                parent: fr_hip,
                joint: revolute(fr_hfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, -0.014, 0.0],
                mass: 0.149,
                com: [0.0, -0.016, -0.078],
                inertia: diag[4.2e-4, 4.1e-4, 2.4e-5],
            },
            fr_lower {
                parent: fr_upper,
                joint: revolute(fr_kfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, -0.037, -0.16],
                mass: 0.031,
                com: [0.0, -0.007, -0.079],
                inertia: diag[1.2e-4, 1.2e-4, 2.1e-6],
            },
            hl_hip {
                parent: base,
                joint: revolute(hl_haa, [1.0, 0.0, 0.0]),
                xyz: [-0.1946, 0.0875, 0.0],
                mass: 0.149,
                com: [0.0, 0.014, 0.0],
                inertia: diag[4.0e-5, 7.0e-5, 4.0e-5],
            },
            hl_upper {
                parent: hl_hip,
                joint: revolute(hl_hfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, 0.014, 0.0],
                mass: 0.149,
                com: [0.0, 0.016, -0.078],
                inertia: diag[4.2e-4, 4.1e-4, 2.4e-5],
            },
            hl_lower {
                parent: hl_upper,
                joint: revolute(hl_kfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, 0.037, -0.16],
                mass: 0.031,
                com: [0.0, 0.007, -0.079],
                inertia: diag[1.2e-4, 1.2e-4, 2.1e-6],
            },
            hr_hip {
                parent: base,
                joint: revolute(hr_haa, [1.0, 0.0, 0.0]),
                xyz: [-0.1946, -0.0875, 0.0],
                mass: 0.149,
                com: [0.0, -0.014, 0.0],
                inertia: diag[4.0e-5, 7.0e-5, 4.0e-5],
            },
            hr_upper {
                parent: hr_hip,
                joint: revolute(hr_hfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, -0.014, 0.0],
                mass: 0.149,
                com: [0.0, -0.016, -0.078],
                inertia: diag[4.2e-4, 4.1e-4, 2.4e-5],
            },
            hr_lower {
                parent: hr_upper,
                joint: revolute(hr_kfe, [0.0, 1.0, 0.0]),
                xyz: [0.0, -0.037, -0.16],
                mass: 0.031,
                com: [0.0, -0.007, -0.079],
                inertia: diag[1.2e-4, 1.2e-4, 2.1e-6],
            },
        ],
        forces: [
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
            t_fl_haa, t_fl_hfe, t_fl_kfe, t_fr_haa, t_fr_hfe, t_fr_kfe,
            t_hl_haa, t_hl_hfe, t_hl_kfe, t_hr_haa, t_hr_hfe, t_hr_kfe,
        ],
        constraints: [
            position(fl_lower, [0.0, 0.008, -0.16]) == [fl_x, fl_y, 0.0],
            position(fr_lower, [0.0, -0.008, -0.16]) == [fr_x, fr_y, 0.0],
            position(hl_lower, [0.0, 0.008, -0.16]) == [hl_x, hl_y, 0.0],
            position(hr_lower, [0.0, -0.008, -0.16]) == [hr_x, hr_y, 0.0],
            $($extra)*
        ],
        $(frames: [$($frame)*],)?
    }
}
    };
}

quadruped_system!(
    /// The quadruped standing on its four feet.
    Quadruped,
    []
);
