//! The URDF reader's unit tests: mimic refusals and the right-angle rule.

use super::numbers::right_angle;
use super::*;

/// A revolute joint and a finger on a prismatic joint that mimics it
/// (as the Panda's second finger mimics the first).
const MIMIC: &str = r#"<robot name="r">
  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="finger"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="finger_joint" type="prismatic"><parent link="arm"/><child link="finger"/>
<mimic joint="shoulder"/>
  </joint>
</robot>"#;

fn read(locked: &[&str]) -> syn::Result<Robot> {
    read_text(MIMIC, locked)
}

fn read_text(text: &str, locked: &[&str]) -> syn::Result<Robot> {
    let path = std::env::temp_dir().join(format!(
        "constrained-mimic-{}-{}.urdf",
        std::process::id(),
        text.len()
    ));
    std::fs::write(&path, text).expect("the temporary directory is writable");
    let literal = LitStr::new(&path.display().to_string(), Span::call_site());
    let list = List {
        items: locked
            .iter()
            .map(|n| Ident::new(n, Span::call_site()))
            .collect(),
        span: Span::call_site(),
    };
    let robot = Robot::read(&literal, Some(&list), None);
    let _ = std::fs::remove_file(&path);
    robot
}

#[test]
fn a_mimic_joint_has_no_coordinate_of_its_own() {
    let robot = read(&[]).expect("a moving mimic joint is read");
    assert_eq!(robot.coordinate_names(), ["shoulder"]);
    let robot = read(&["finger_joint"]).expect("a locked mimic joint is read");
    let names: Vec<String> = robot
        .coordinates()
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(names, ["shoulder"]);
}

#[test]
fn a_mimic_follows_one_coordinate_of_a_joint_that_is_no_mimic() {
    let cases = [
        // A mimic of a mimic.
        (
            MIMIC.replace(
                "</robot>",
                r#"<link name="tip"/><joint name="tip_joint" type="revolute"><parent link="finger"/><child link="tip"/>
<mimic joint="finger_joint"/></joint></robot>"#,
            ),
            ":10: joint `tip_joint`: <mimic> names `finger_joint`, itself a mimic",
        ),
        // A joint of three coordinates followed.
        (
            MIMIC.replace(r#"type="revolute""#, r#"type="planar""#),
            ":7: joint `finger_joint`: <mimic> names `shoulder`, which has more than one coordinate",
        ),
        // A mimic that is not one coordinate.
        (
            MIMIC.replace(r#"type="prismatic""#, r#"type="floating""#),
            ":7: joint `finger_joint`: only a revolute, continuous or prismatic joint can <mimic>",
        ),
    ];
    for (text, expected) in cases {
        let message = read_text(&text, &[]).err().map(|e| e.to_string());
        assert!(
            message.as_deref().is_some_and(|m| m.contains(expected)),
            "{message:?}"
        );
    }
}

#[test]
fn a_decimal_is_a_right_angle_only_to_double_precision() {
    let cases = [
        ("1.5707963267948966", Some(1)),
        ("-1.5707963267948966", Some(-1)),
        ("1.570796326794897", Some(1)), // the next double up
        ("3.141592653589793", Some(2)),
        ("-3.14159265358979", None), // 4.5 ε|π| from −π: as written
        ("4.71238898038469", Some(3)),
        ("1.5707963267949", None), // 10 ε|π/2| off
        ("1.57079632679", None),
        ("1.5708", None),
        ("1.570800", None),
        ("0", None),
        ("-0.0", None),
        ("1e300", None),
    ];
    for (text, expected) in cases {
        assert_eq!(right_angle(text, None), expected, "{text}");
    }
}

#[test]
fn right_angles_within_a_tolerance_only_when_asked() {
    // The UR5's `1.570796325` is 1.8e-9 from π/2; the xArm7's `1.5708`
    // 3.7e-6.
    let cases = [
        ("1.570796325", 1e-9, None),
        ("1.570796325", 1e-8, Some(1)),
        ("-1.570796325", 1e-8, Some(-1)),
        ("1.5708", 1e-6, None),
        ("1.5708", 1e-5, Some(1)),
        ("3.1416", 1e-4, Some(2)),
        ("0.5", 1e-2, None),
        // The double-precision rule still holds under a smaller tolerance.
        ("1.5707963267948966", 1e-20, Some(1)),
    ];
    for (text, snap, expected) in cases {
        assert_eq!(
            right_angle(text, Some(snap)),
            expected,
            "{text} within {snap}"
        );
    }
    let literal = |t: &str| LitFloat::new(t, Span::call_site());
    assert_eq!(tolerance(&literal("1e-6")).ok(), Some(1e-6));
    for bad in ["0.0", "0.5", "1e400"] {
        let message = tolerance(&literal(bad)).err().map(|e| e.to_string());
        assert!(message.is_some_and(|m| m.contains("in (0, 0.01]")), "{bad}");
    }
}

#[test]
fn mimic_on_a_fixed_joint_is_ignored() {
    // TALOS's grippers write <mimic> on joints of type `fixed`.
    let text = MIMIC.replace(r#"type="prismatic""#, r#"type="fixed""#);
    let robot = read_text(&text, &[]).expect("a fixed mimic joint is read");
    assert_eq!(robot.coordinate_names(), ["shoulder"]);
}

/// An arm and a gripper joint moving a link without `<inertial>` (as
/// romeo_laas_small.urdf's grippers are written).
const MASSLESS: &str = r#"<robot name="r">
  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="jaw"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0.0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="gripper" type="revolute"><parent link="arm"/><child link="jaw"/><axis xyz="0 1 0"/></joint>
</robot>"#;

#[test]
fn a_joint_that_moves_only_massless_links_is_refused_at_its_line() {
    let message = read_text(MASSLESS, &[])
        .err()
        .expect("a joint without inertia below it is refused")
        .to_string();
    assert!(
        message.contains(".urdf:6: joint `gripper` moves only massless links (from `jaw` down"),
        "{message}"
    );
    assert!(message.contains("locked: [gripper]"), "{message}");
    // Locked, it moves nothing.
    let robot = read_text(MASSLESS, &["gripper"]).expect("the locked gripper is read");
    assert_eq!(robot.coordinate_names(), ["shoulder"]);
    // Mass anywhere below the joint gives its column inertia.
    let below = MASSLESS.replace(
        "</robot>",
        r#"<link name="pad"><inertial><mass value="0.1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="pad_joint" type="fixed"><parent link="jaw"/><child link="pad"/></joint>
</robot>"#,
    );
    read_text(&below, &[]).expect("a massive link below the jaw");
    // As does a massive link moved by a mimic of the joint.
    let mimic = MASSLESS.replace(
        "</robot>",
        r#"<link name="other"><inertial><mass value="0.1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <joint name="other_jaw" type="revolute"><parent link="arm"/><child link="other"/><axis xyz="0 1 0"/><mimic joint="gripper" multiplier="-1"/></joint>
</robot>"#,
    );
    let robot = read_text(&mimic, &[]).expect("the jaw's mimic moves a mass");
    assert_eq!(robot.coordinate_names(), ["shoulder", "gripper"]);
}
