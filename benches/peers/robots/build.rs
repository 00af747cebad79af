//! Writes the robots' `constrained_system!` invocations with the absolute
//! paths of their URDFs, which live in the peers' virtual environment
//! (`benches/peers/.venv`, where `benches/peers/run.sh` installs the
//! `example-robot-data` wheel): the directory's name carries the Python
//! version, so it is found here rather than written in the source.
//! `EXAMPLE_ROBOT_DATA` may name the `robots` directory instead.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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

fn main() {
    let robots = robots_directory();
    let panda = robots.join("panda_description/urdf/panda.urdf");
    let ur5 = robots.join("ur_description/urdf/ur5_robot.urdf");
    let mut out = String::new();
    let torques = |n: usize| {
        (1..=n)
            .map(|k| format!("tau{k}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (name, path, locked, joints, what) in [
        (
            "PandaUrdf",
            &panda,
            "locked: [panda_finger_joint1, panda_finger_joint2],",
            7,
            "The Franka Emika Panda from example-robot-data's URDF, its fingers held closed",
        ),
        (
            "Ur5Urdf",
            &ur5,
            "",
            6,
            "The Universal Robots UR5 from example-robot-data's URDF",
        ),
    ] {
        assert!(path.is_file(), "{} is missing", path.display());
        println!("cargo::rerun-if-changed={}", path.display());
        let _ = writeln!(
            out,
            "constrained::constrained_system! {{\n    /// {what}; a motor torque per joint.\n    \
             pub struct {name} {{\n        inputs: [{tau}],\n        urdf: {path:?},\n        \
             {locked}\n        forces: [{tau}],\n    }}\n}}\n",
            tau = torques(joints),
            path = path.display().to_string(),
        );
    }
    let file = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("robots.rs");
    std::fs::write(file, out).expect("OUT_DIR is writable");
    println!("cargo::rerun-if-changed=build.rs");
}
