//! Writes the robots' `constrained_system!` invocations with the absolute
//! paths of their URDFs, which live in the peers' virtual environment
//! (`benches/peers/.venv`, where `benches/peers/run.sh` installs the
//! `example-robot-data` wheel): the directory's name carries the Python
//! version, so it is found here rather than written in the source.
//! `EXAMPLE_ROBOT_DATA` may name the `robots` directory instead.
//!
//! Every robot of the Robots rows is read from the wheel's file as
//! written: no copy is adjusted. The Contacts rows' Go1 (`go1.rs`, for
//! `src/bin/contacts.rs`) is the wheel's file with a floating root joint
//! added, the one change a floating base needs (see [`go1`]). `ROBOTS` is the one table of the robots: besides each
//! invocation this writes its `Urdf` implementation (the file's path
//! relative to the `robots` directory, the locked joints and whether
//! `<mimic>` is read, which `benches/peers/robots.cpp` reads back from the
//! reference file to build Pinocchio's model of the same joints) and
//! `robots`, which visits them in this order. The implementation's
//! methods are forced inline: a wrapper left as a call of its own added
//! measurably to `mass_matrix`'s time, which must be the generated
//! method's alone.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A robot: its struct, its short name (the reference file's), its file
/// under `robots`, its locked joints, whether it is timed and what it is.
struct Robot {
    name: &'static str,
    short: &'static str,
    file: &'static str,
    locked: &'static [&'static str],
    /// Pinocchio's `aba` refuses a model with mimic joints: such a robot's
    /// answers are compared, not timed.
    mimic: bool,
    what: &'static str,
}

/// The G1's arms: shoulder, elbow and wrist joints of both sides.
const G1_ARMS: &[&str] = &[
    "left_shoulder_pitch_joint",
    "left_shoulder_roll_joint",
    "left_shoulder_yaw_joint",
    "left_elbow_joint",
    "left_wrist_roll_joint",
    "left_wrist_pitch_joint",
    "left_wrist_yaw_joint",
    "right_shoulder_pitch_joint",
    "right_shoulder_roll_joint",
    "right_shoulder_yaw_joint",
    "right_elbow_joint",
    "right_wrist_roll_joint",
    "right_wrist_pitch_joint",
    "right_wrist_yaw_joint",
];

/// The section every robot here is written with: its large methods also
/// compiled for AVX, chosen at run time (docs/dsl.md, "Run-time
/// dispatch"). The binaries are built for plain x86-64, as Pinocchio's
/// wheel is; `benches/peers/build_time.sh` removes the line, since its
/// rows measure a system as written without it.
const DISPATCH: &str = "dispatch: [avx],";

const ROBOTS: &[Robot] = &[
    Robot {
        name: "PandaUrdf",
        short: "panda",
        file: "panda_description/urdf/panda.urdf",
        locked: &["panda_finger_joint1", "panda_finger_joint2"],
        mimic: false,
        what: "The Franka Emika Panda, its fingers held closed",
    },
    Robot {
        name: "Ur5Urdf",
        short: "ur5",
        file: "ur_description/urdf/ur5_robot.urdf",
        locked: &[],
        mimic: false,
        what: "The Universal Robots UR5",
    },
    // The grippers need no lock: in this file each gripper's fingers
    // carry `<mimic>` on fixed joints (which neither reader moves), and
    // the one revolute joint of each gripper is a coordinate on both sides.
    Robot {
        name: "TalosUrdf",
        short: "talos",
        file: "talos_data/robots/talos_reduced.urdf",
        locked: &[],
        mimic: false,
        what: "PAL Robotics' TALOS (talos_reduced), fixed base",
    },
    Robot {
        name: "Xarm7Urdf",
        short: "xarm7",
        file: "xarm_description/urdf/xarm7.urdf",
        locked: &[],
        mimic: false,
        what: "The UFactory xArm7",
    },
    // Kinova's Jaco 2 (j2s6s200); three of its joints are `continuous`,
    // an angle here and (cos, sin) in Pinocchio's q.
    Robot {
        name: "KinovaUrdf",
        short: "kinova",
        file: "kinova_description/robots/kinova.urdf",
        locked: &[],
        mimic: false,
        what: "The Kinova Jaco 2 j2s6s200",
    },
    // The G1's `floating_base_joint` is commented out in this file (its
    // own note: for MuJoCo), so as written the pelvis is fixed to the world
    // on both sides: no copy and no lock of a floating joint is needed.
    Robot {
        name: "G1ArmsLockedUrdf",
        short: "g1_arms_locked",
        file: "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        locked: G1_ARMS,
        mimic: false,
        what: "The Unitree G1 (29 joints), fixed base, its 14 arm joints held at zero",
    },
    Robot {
        name: "G1Urdf",
        short: "g1",
        file: "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        locked: &[],
        mimic: false,
        what: "The Unitree G1 (29 joints), fixed base",
    },
    // IIT's iCub as its exporter wrote it: every frame turned by `1.5708`
    // (not π/2) and the axes carrying `6e-17` leftovers, so that no
    // placement is sparse and `M` is formed in world axes.
    Robot {
        name: "IcubUrdf",
        short: "icub",
        file: "icub_description/robots/icub_reduced.urdf",
        locked: &[],
        mimic: false,
        what: "IIT's iCub (icub_reduced, 29 joints), fixed base",
    },
    Robot {
        name: "PandaMimicUrdf",
        short: "panda_mimic",
        file: "panda_description/urdf/panda.urdf",
        locked: &[],
        mimic: true,
        what: "The Franka Emika Panda with its second finger following the first (`<mimic>`)",
    },
];

/// A named frame of the Kinematics rows: fixed in the URDF link `body`, at
/// `xyz` turned by `rpy` in that link's frame (`frames:` of the DSL;
/// Pinocchio's `OP_FRAME` on the link's `BODY` frame in `kinematics.cpp`).
struct Frame {
    name: &'static str,
    body: &'static str,
    xyz: [f64; 3],
    rpy: [f64; 3],
}

/// A robot of the Kinematics rows (`src/bin/kinematics.rs`): a robot as
/// above with its frames; the first frame is the one timed.
struct Framed {
    name: &'static str,
    short: &'static str,
    file: &'static str,
    locked: &'static [&'static str],
    frames: &'static [Frame],
    what: &'static str,
}

/// A foot of the Go1 (each `*_foot` link, merged into its calf by a
/// fixed joint), at the bottom of its 0.02 m sphere.
const fn go1_sole(name: &'static str, body: &'static str) -> Frame {
    Frame {
        name,
        body,
        xyz: [0.0, 0.0, -0.02],
        rpy: [0.0, 0.0, 0.0],
    }
}

/// The robots of the Kinematics and derivatives rows. Each frame is on a
/// link merged into its parent by fixed joints (the Panda's `panda_hand`
/// behind two, turned −π/4; the G1's `right_rubber_hand`; the Go1's feet)
/// but the G1's sole, on the ankle's own link; the Panda's tool point is
/// turned every way so that no placement is trivial.
const FRAMED: &[Framed] = &[
    Framed {
        name: "PandaFrames",
        short: "panda",
        file: "panda_description/urdf/panda.urdf",
        locked: &["panda_finger_joint1", "panda_finger_joint2"],
        frames: &[Frame {
            name: "tool",
            body: "panda_hand",
            xyz: [0.01, -0.02, 0.1034],
            rpy: [0.1, -0.2, 0.3],
        }],
        what: "The Franka Emika Panda, its fingers held closed, a tool point on its hand",
    },
    // The sole: midway between the ankle link's four contact spheres
    // (x −0.05 and 0.12, z −0.03, radius 0.005).
    Framed {
        name: "G1Frames",
        short: "g1",
        file: "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        locked: &[],
        frames: &[
            Frame {
                name: "left_sole",
                body: "left_ankle_roll_link",
                xyz: [0.035, 0.0, -0.035],
                rpy: [0.0, 0.0, 0.0],
            },
            Frame {
                name: "right_palm",
                body: "right_rubber_hand",
                xyz: [0.05, -0.01, 0.0],
                rpy: [0.0, 0.4, -0.3],
            },
        ],
        what: "The Unitree G1 (29 joints), fixed base, frames at a sole and a palm",
    },
    // The file's `floating_base` joint is `fixed`: as written the trunk is
    // fixed to the world on both sides.
    Framed {
        name: "Go1Frames",
        short: "go1",
        file: "go1_description/urdf/go1.urdf",
        locked: &[],
        frames: &[
            go1_sole("fl_sole", "FL_foot"),
            go1_sole("fr_sole", "FR_foot"),
            go1_sole("rl_sole", "RL_foot"),
            go1_sole("rr_sole", "RR_foot"),
        ],
        what: "The Unitree Go1 (12 joints), fixed trunk, a frame under each foot",
    },
];

/// `example-robot-data`'s `robots` directory in the peers' environment.
fn robots_directory() -> PathBuf {
    println!("cargo::rerun-if-env-changed=EXAMPLE_ROBOT_DATA");
    if let Ok(dir) = std::env::var("EXAMPLE_ROBOT_DATA") {
        return PathBuf::from(dir);
    }
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let lib = Path::new(&manifest).join("../.venv/lib");
    let entries = std::fs::read_dir(&lib).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (run benches/peers/run.sh, which installs example-robot-data)",
            lib.display()
        )
    });
    entries
        .filter_map(Result::ok)
        .map(|e| {
            e.path()
                .join("site-packages/cmeel.prefix/share/example-robot-data/robots")
        })
        .find(|p| p.is_dir())
        .unwrap_or_else(|| panic!("no example-robot-data under {}", lib.display()))
}

/// The number of moving joints of `file` once `locked` are held and mimic
/// joints (if read) follow: the system's `N`, needed before the macro runs
/// to write the torques and the impl. Counts `revolute`, `continuous` and
/// `prismatic` joints, the only kinds these robots move with. A miscount
/// does not compile: `names` returns `COORDINATES`, an array of `DOF`.
fn joints(file: &str, locked: &[&str], mimic: bool) -> usize {
    let written = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{file}: {e}"));
    // Without comments (the G1's commented-out floating joint).
    let mut text = String::new();
    let mut rest = written.as_str();
    while let Some(start) = rest.find("<!--") {
        text.push_str(&rest[..start]);
        let end = rest[start..].find("-->").expect("a closed comment");
        rest = &rest[start + end + 3..];
    }
    text.push_str(rest);
    // Each `<joint ...>` element with its body up to `</joint>` (joint
    // elements inside `<transmission>` have no `type`).
    let mut n = 0;
    for element in text.split("<joint").skip(1) {
        let head = &element[..element.find('>').expect("a closed tag")];
        let attribute = |key: &str| {
            let at = head.find(&format!("{key}=\""))? + key.len() + 2;
            Some(&head[at..at + head[at..].find('"')?])
        };
        let (Some(name), Some(kind)) = (attribute("name"), attribute("type")) else {
            continue;
        };
        let body = &element[..element.find("</joint>").unwrap_or(element.len())];
        let moves = matches!(kind, "revolute" | "continuous" | "prismatic");
        let follows = mimic && body.contains("<mimic");
        if moves && !follows && !locked.contains(&name) {
            n += 1;
        }
    }
    n
}

/// `file` (under `robots`) with its root link `root` on a `floating` joint
/// `root_joint` from a `world` link, which is what Pinocchio's
/// `buildModel(file, JointModelFreeFlyer())` adds on its side; written to
/// `out/copy`, whose path it returns. `robot` is the file's `<robot>` tag.
fn floating(
    robots: &Path,
    (file, robot, root): (&str, &str, &str),
    out: &Path,
    copy: &str,
) -> PathBuf {
    let path = robots.join(file);
    println!("cargo::rerun-if-changed={}", path.display());
    let written =
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        written.contains(robot),
        "{} names another robot",
        path.display()
    );
    let joint = format!(
        "\n  <link name=\"world\"/>\n  <joint name=\"root_joint\" type=\"floating\">\n    \
         <parent link=\"world\"/>\n    <child link=\"{root}\"/>\n  </joint>"
    );
    let floating = written.replacen(robot, &format!("{robot}{joint}"), 1);
    let copy = out.join(copy);
    std::fs::write(&copy, floating).expect("OUT_DIR is writable");
    copy
}

/// The Unitree Go1 of the Contacts rows: the wheel's `go1.urdf` as
/// written, its root link `base` on a floating joint ([`floating`]; the
/// file has none: its base is fixed to the world as written). Writes the
/// copy and the invocation (`go1.rs`) into `out`: the four feet are the
/// foot links' origins held where the state puts them, a motor torque per
/// joint.
fn go1(robots: &Path, out: &Path) {
    let file = "go1_description/urdf/go1.urdf";
    let copy = floating(
        robots,
        (file, "<robot name=\"go1\">", "base"),
        out,
        "go1_floating.urdf",
    );
    let torques = (1..=12)
        .map(|k| format!("t{k}"))
        .collect::<Vec<_>>()
        .join(", ");
    let feet = ["FL", "FR", "RL", "RR"];
    let places = feet
        .iter()
        .map(|f| {
            let f = f.to_lowercase();
            format!("{f}_x, {f}_y, {f}_z")
        })
        .collect::<Vec<_>>()
        .join(", ");
    let rows = feet
        .iter()
        .map(|f| {
            let l = f.to_lowercase();
            format!("position({f}_foot, [0.0, 0.0, 0.0]) == [{l}_x, {l}_y, {l}_z],")
        })
        .collect::<Vec<_>>()
        .join("\n            ");
    let invocation = format!(
        "constrained::constrained_system! {{\n    /// The Unitree Go1 of example-robot-data's \
         `go1_description/urdf/go1.urdf` on a floating root joint, standing on its\n    \
         /// four feet (the foot links' origins held at `(x, y, z)` each), a motor torque per joint.\n    \
         pub struct Go1 {{\n        parameters: [{places}],\n        inputs: [{torques}],\n        \
         urdf: {copy:?},\n        {DISPATCH}\n        forces: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, {torques}],\n        \
         constraints: [\n            {rows}\n        ],\n    }}\n}}\n",
        copy = copy.display().to_string(),
    );
    std::fs::write(out.join("go1.rs"), invocation).expect("OUT_DIR is writable");
}

/// The points of each G1 foot that stand, on its `*_ankle_roll_link`:
/// three of the four contact spheres the file gives each ankle (centres
/// at `x` −0.05 and 0.12, `y` ±0.025 or ±0.03, `z` −0.03).
const G1_SOLE_POINTS: [[f64; 3]; 3] = [
    [-0.05, 0.025, -0.03],
    [-0.05, -0.025, -0.03],
    [0.12, 0.03, -0.03],
];

/// The Unitree G1 (29 joints) of the redundant-contacts rows: the wheel's
/// `g1_29dof_rev_1_0.urdf`, its `pelvis` on a floating joint ([`floating`];
/// the file's own is commented out), standing on both feet, each held at
/// the three points of [`G1_SOLE_POINTS`] where the state puts them:
/// eighteen rows (and the quaternion's norm) of rank twelve on the feet
/// (`g1_standing.rs` in `out`). Unpowered: `λ` holds it up.
fn g1_standing(robots: &Path, out: &Path) {
    let file = "g1_description/urdf/g1_29dof_rev_1_0.urdf";
    let robot = "<robot name=\"g1_29dof_rev_1_0\">";
    let copy = floating(robots, (file, robot, "pelvis"), out, "g1_floating.urdf");
    let mut places = Vec::new();
    let mut rows = Vec::new();
    for side in ["left", "right"] {
        for (k, [x, y, z]) in G1_SOLE_POINTS.iter().enumerate() {
            let names = ["x", "y", "z"].map(|a| format!("{}{k}_{a}", &side[..1]));
            rows.push(format!(
                "position({side}_ankle_roll_link, [{x:?}, {y:?}, {z:?}]) == [{}],",
                names.join(", ")
            ));
            places.extend(names);
        }
    }
    let invocation = format!(
        "constrained::constrained_system! {{\n    /// The Unitree G1 of example-robot-data's \
         `g1_description/urdf/g1_29dof_rev_1_0.urdf` on a floating root joint, standing on\n    \
         /// three points of each foot (held at `(x, y, z)` each), unpowered.\n    \
         pub struct G1Standing {{\n        parameters: [{places}],\n        urdf: {copy:?},\n        {DISPATCH}\n        \
         constraints: [\n            {rows}\n        ],\n    }}\n}}\n\n\
         /// The points of each foot held, in its `*_ankle_roll_link`'s frame.\n\
         const SOLE_POINTS: [[f64; 3]; 3] = {G1_SOLE_POINTS:?};\n",
        places = places.join(", "),
        rows = rows.join("\n            "),
        copy = copy.display().to_string(),
    );
    std::fs::write(out.join("g1_standing.rs"), invocation).expect("OUT_DIR is writable");
    g1_flat(&copy, out);
}

/// The sole of each G1 foot as a flat contact: a point under the ankle
/// roll link (midway between its file's contact spheres, as the kinematics
/// rows' `left_sole`) held in place and the link's attitude held, six rows
/// a foot (`g1_flat.rs` in `out`): what Pinocchio's `CONTACT_6D` holds.
const G1_SOLE: [f64; 3] = [0.035, 0.0, -0.035];

/// The Unitree G1 of the flat-feet rows, from the floating copy `copy`:
/// each foot's sole point held at `(x, y, z)` and its attitude at
/// `(roll, pitch, yaw)` (`Rz Ry Rx`), twelve independent rows (and the
/// quaternion's norm); a frame at each sole, from which the states place
/// them. Unpowered.
fn g1_flat(copy: &Path, out: &Path) {
    let [x, y, z] = G1_SOLE;
    let mut places = Vec::new();
    let mut rows = Vec::new();
    let mut frames = Vec::new();
    for side in ["left", "right"] {
        let s = &side[..1];
        let at = ["x", "y", "z"].map(|a| format!("{s}_{a}"));
        let turned = ["roll", "pitch", "yaw"].map(|a| format!("{s}_{a}"));
        rows.push(format!(
            "position({side}_ankle_roll_link, [{x:?}, {y:?}, {z:?}]) == [{}],",
            at.join(", ")
        ));
        rows.push(format!(
            "orientation({side}_ankle_roll_link) == [{}],",
            turned.join(", ")
        ));
        frames.push(format!(
            "{side}_sole {{ body: {side}_ankle_roll_link, xyz: [{x:?}, {y:?}, {z:?}] }}"
        ));
        places.extend(at);
        places.extend(turned);
    }
    let invocation = format!(
        "constrained::constrained_system! {{\n    /// The Unitree G1 of example-robot-data's \
         `g1_description/urdf/g1_29dof_rev_1_0.urdf` on a floating root joint, standing on\n    \
         /// two flat feet (each sole held at `(x, y, z)`, its attitude at `(roll, pitch, yaw)`), unpowered.\n    \
         pub struct G1Flat {{\n        parameters: [{places}],\n        urdf: {copy:?},\n        {DISPATCH}\n        \
         frames: [{frames}],\n        \
         constraints: [\n            {rows}\n        ],\n    }}\n}}\n\n\
         /// The sole point of each foot, in its `*_ankle_roll_link`'s frame.\n\
         const SOLE: [f64; 3] = {G1_SOLE:?};\n",
        places = places.join(", "),
        frames = frames.join(", "),
        rows = rows.join("\n            "),
        copy = copy.display().to_string(),
    );
    std::fs::write(out.join("g1_flat.rs"), invocation).expect("OUT_DIR is writable");
}

/// The methods of `Framed` that do not depend on a frame: name,
/// arguments, type and body, `N` standing for the number of joints.
const WHOLE: &[(&str, &str, &str, &str)] = &[
    (
        "com",
        "q: &Vector<N>",
        "Vector3<f64>",
        "self.center_of_mass(q, 0.0)",
    ),
    (
        "com_jacobian",
        "q: &Vector<N>",
        "SMatrix<f64, 3, N>",
        "self.center_of_mass_jacobian(q, 0.0)",
    ),
    (
        "com_and_jacobian",
        "q: &Vector<N>",
        "(Vector3<f64>, SMatrix<f64, 3, N>)",
        "self.center_of_mass_and_jacobian(q, 0.0)",
    ),
    (
        "com_velocity",
        "q: &Vector<N>, v: &Vector<N>",
        "Vector3<f64>",
        "self.center_of_mass_velocity(q, v, 0.0)",
    ),
    (
        "centroidal",
        "q: &Vector<N>",
        "SMatrix<f64, 6, N>",
        "self.centroidal_map(q, 0.0)",
    ),
    (
        "centroidal_bias",
        "q: &Vector<N>, v: &Vector<N>",
        "SVector<f64, 6>",
        "self.centroidal_map_bias(q, v, 0.0)",
    ),
    (
        "tau",
        "q: &Vector<N>, v: &Vector<N>, a: &Vector<N>",
        "Vector<N>",
        "self.inverse_dynamics(q, v, a, 0.0).value()",
    ),
    (
        "tau_jacobian",
        "q: &Vector<N>, v: &Vector<N>, a: &Vector<N>",
        "(Matrix<N>, Matrix<N>)",
        "self.inverse_dynamics_jacobian(q, v, a, 0.0).value()",
    ),
    (
        "tau_jacobian_to",
        "q: &Vector<N>, v: &Vector<N>, a: &Vector<N>, out: &mut (Matrix<N>, Matrix<N>)",
        "()",
        "self.inverse_dynamics_jacobian_to(q, v, a, 0.0, out).value()",
    ),
    (
        "mass",
        "q: &Vector<N>",
        "Matrix<N>",
        "self.mass_matrix(q, 0.0).value()",
    ),
    (
        "derivatives",
        "q: &Vector<N>, v: &Vector<N>",
        "Jacobians<f64, N, N>",
        "self.acceleration_jacobian(q, v, 0.0).value()",
    ),
    (
        "derivatives_to",
        "q: &Vector<N>, v: &Vector<N>, out: &mut Jacobians<f64, N, N>",
        "()",
        "self.acceleration_jacobian_to(q, v, 0.0, out).value()",
    ),
];

/// `WHOLE`'s methods for a robot of `n` joints.
fn whole_methods(n: usize) -> String {
    let n = n.to_string();
    WHOLE
        .iter()
        .map(|(name, args, ty, body)| {
            format!(
                "    #[inline(always)]\n    fn {name}(&self, {}) -> {} {{\n        {body}\n    }}\n",
                args.replace('N', &n),
                ty.replace('N', &n)
            )
        })
        .collect()
}

/// A robot's frames as its `frames:` section and as its `FRAMES` table.
fn frame_lists(r: &Framed) -> (String, String) {
    let frames = r
        .frames
        .iter()
        .map(|f| {
            format!(
                "{} {{ body: {}, xyz: {:?}, rpy: {:?} }}",
                f.name, f.body, f.xyz, f.rpy
            )
        })
        .collect::<Vec<_>>()
        .join(",\n            ");
    let table = r
        .frames
        .iter()
        .map(|f| {
            format!(
                "Frame {{ name: {:?}, body: {:?}, xyz: {:?}, rpy: {:?} }}",
                f.name, f.body, f.xyz, f.rpy
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    (frames, table)
}

/// One robot of the Kinematics rows: its `constrained_system!` (`path`,
/// its URDF; `n` joints) and its `Framed` implementation.
fn framed_system(r: &Framed, path: &str, n: usize) -> String {
    let torques = (1..=n)
        .map(|k| format!("tau{k}"))
        .collect::<Vec<_>>()
        .join(", ");
    let locked = if r.locked.is_empty() {
        String::new()
    } else {
        format!("locked: [{}],", r.locked.join(", "))
    };
    let (frames, table) = frame_lists(r);
    // Per method, the frame's generated method by index: called with a
    // constant index, the match folds away.
    let by_frame = |method: &str, args: &str| {
        let arms: String = r
            .frames
            .iter()
            .enumerate()
            .map(|(k, f)| format!("            {k} => self.{}_{method}({args}),\n", f.name))
            .collect();
        format!(
            "match frame {{\n{arms}            _ => panic!(\"no frame {{frame}}\"),\n        }}"
        )
    };
    let arguments = (0..n)
        .map(|k| format!("t[{k}]"))
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "constrained::constrained_system! {{\n    /// {what}, from example-robot-data's \
         `{file}`; a motor torque per joint.\n    pub struct {name} {{\n        \
         inputs: [{torques}],\n        urdf: {path:?},\n        {locked}\n        {DISPATCH}\n        \
         forces: [{torques}],\n        frames: [\n            {frames}\n        ],\n        \
         derivatives: [inverse_dynamics],\n    }}\n}}\n\n\
         impl Framed<{n}> for {name} {{\n    const NAME: &'static str = {short:?};\n    \
         const FILE: &'static str = {file:?};\n    \
         const LOCKED: &'static [&'static str] = &{locked_list:?};\n    \
         const FRAMES: &'static [Frame] = &[{table}];\n    \
         fn names() -> [&'static str; {n}] {{\n        Self::COORDINATES\n    }}\n    \
         #[inline(always)]\n    fn with_torques(t: &Vector<{n}>) -> Self {{\n        Self::new({arguments})\n    }}\n    \
         #[inline(always)]\n    fn placement(&self, frame: usize, q: &Vector<{n}>) -> (Matrix3<f64>, Vector3<f64>) {{\n        {placement}\n    }}\n    \
         #[inline(always)]\n    fn jacobian(&self, frame: usize, q: &Vector<{n}>) -> SMatrix<f64, 6, {n}> {{\n        {jacobian}\n    }}\n    \
         #[inline(always)]\n    fn velocity(&self, frame: usize, q: &Vector<{n}>, v: &Vector<{n}>) -> SVector<f64, 6> {{\n        {velocity}\n    }}\n    \
         #[inline(always)]\n    fn bias(&self, frame: usize, q: &Vector<{n}>, v: &Vector<{n}>) -> SVector<f64, 6> {{\n        {bias}\n    }}\n\
         {whole}}}\n\n",
        what = r.what,
        file = r.file,
        name = r.name,
        short = r.short,
        locked_list = r.locked,
        placement = by_frame("placement", "q, 0.0"),
        jacobian = by_frame("jacobian", "q, 0.0"),
        velocity = by_frame("velocity", "q, v, 0.0"),
        bias = by_frame("acceleration_bias", "q, v, 0.0"),
        whole = whole_methods(n),
    )
}

/// The Kinematics rows' systems and their `Framed` implementations
/// (`src/bin/kinematics.rs`; each asks for `inverse_dynamics_jacobian`
/// too), and `framed`, which visits them in the table's order.
fn kinematics(robots: &Path) -> String {
    let mut out = String::new();
    let mut visit = String::new();
    for r in FRAMED {
        let path = robots.join(r.file);
        assert!(path.is_file(), "{} is missing", path.display());
        println!("cargo::rerun-if-changed={}", path.display());
        let path = path.display().to_string();
        let n = joints(&path, r.locked, false);
        out.push_str(&framed_system(r, &path, n));
        let _ = writeln!(visit, "    visit.robot::<{}, {n}>();", r.name);
    }
    let _ = writeln!(
        out,
        "/// Visits every robot with frames, in the order of build.rs's table.\n\
         fn framed(visit: &mut impl Visit) {{\n{visit}}}"
    );
    out
}

fn main() {
    let robots = robots_directory();
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    go1(&robots, &out_dir);
    g1_standing(&robots, &out_dir);
    let mut out = String::new();
    let mut visit = String::new();
    for r in ROBOTS {
        let path = robots.join(r.file);
        assert!(path.is_file(), "{} is missing", path.display());
        println!("cargo::rerun-if-changed={}", path.display());
        let path = path.display().to_string();
        let n = joints(&path, r.locked, r.mimic);
        let torques = (1..=n)
            .map(|k| format!("tau{k}"))
            .collect::<Vec<_>>()
            .join(", ");
        let locked = if r.locked.is_empty() {
            String::new()
        } else {
            format!("locked: [{}],", r.locked.join(", "))
        };
        let arguments = (0..n)
            .map(|k| format!("t[{k}]"))
            .collect::<Vec<_>>()
            .join(", ");
        let _ = writeln!(
            out,
            "constrained::constrained_system! {{\n    /// {what}, from example-robot-data's \
             `{file}`; a motor torque per joint.\n    pub struct {name} {{\n        \
             inputs: [{torques}],\n        urdf: {path:?},\n        {locked}\n        {DISPATCH}\n        \
             forces: [{torques}],\n    }}\n}}\n\n\
             impl Urdf<{n}> for {name} {{\n    const NAME: &'static str = {short:?};\n    \
             const FILE: &'static str = {file:?};\n    \
             const LOCKED: &'static [&'static str] = &{locked_list:?};\n    \
             const MIMIC: bool = {mimic};\n    \
             fn names() -> [&'static str; {n}] {{\n        Self::COORDINATES\n    }}\n    \
             #[inline(always)]\n    fn with_torques(t: &Vector<{n}>) -> Self {{\n        Self::new({arguments})\n    }}\n    \
             #[inline(always)]\n    fn qdd(&self, q: &Vector<{n}>, v: &Vector<{n}>) -> Vector<{n}> {{\n        \
             self.acceleration(q, v, 0.0).value()\n    }}\n    \
             #[inline(always)]\n    fn mass(&self, q: &Vector<{n}>) -> Matrix<{n}> {{\n        \
             self.mass_matrix(q, 0.0).value()\n    }}\n    \
             #[inline(always)]\n    fn tau(&self, q: &Vector<{n}>, v: &Vector<{n}>, a: &Vector<{n}>) -> Vector<{n}> {{\n        \
             self.inverse_dynamics(q, v, a, 0.0).value()\n    }}\n    \
             #[inline(always)]\n    fn forces_of(&self, q: &Vector<{n}>, v: &Vector<{n}>) -> Vector<{n}> {{\n        \
             self.forces(q, v, 0.0).value()\n    }}\n}}\n",
            what = r.what,
            file = r.file,
            name = r.name,
            short = r.short,
            locked_list = r.locked,
            mimic = r.mimic,
        );
        let _ = writeln!(visit, "    visit.robot::<{}, {n}>();", r.name);
    }
    let _ = writeln!(
        out,
        "/// Visits every robot, in the order of build.rs's table.\n\
         fn robots(visit: &mut impl Visit) {{\n{visit}}}"
    );
    let file = out_dir.join("robots.rs");
    std::fs::write(file, out).expect("OUT_DIR is writable");
    let file =
        Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("kinematics.rs");
    std::fs::write(file, kinematics(&robots)).expect("OUT_DIR is writable");
    println!("cargo::rerun-if-changed=build.rs");
}
