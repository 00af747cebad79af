//! The `urdf` section's refusals: each names the file and the line of the
//! offending element (files in `tests/data`, read relative to this crate's
//! manifest as the macro reads a user's).

use constrained_codegen::expand;

fn error_of(file: &str, extra: &str) -> String {
    let source = format!("struct R {{ urdf: \"tests/data/{file}\", {extra} }}");
    let tokens: proc_macro2::TokenStream = source.parse().expect("tokens");
    match expand(tokens) {
        Ok(_) => panic!("{file} was accepted"),
        Err(e) => e
            .into_iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n"),
    }
}

#[test]
fn urdf_errors_name_the_file_and_line() {
    let cases = [
        (
            "spherical.urdf",
            "",
            "tests/data/spherical.urdf:5: joint `slide` of type `spherical` is not supported",
        ),
        (
            "mimic.urdf",
            "",
            "tests/data/mimic.urdf:9: joint `j2`: <mimic> names `j9`, which is not a joint of the file",
        ),
        (
            "bad_number.urdf",
            "",
            "bad_number.urdf:6: `value` must be 1 finite numbers, not \"heavy\"",
        ),
        (
            "two_roots.urdf",
            "",
            "two_roots.urdf:2: the links must form one tree",
        ),
        (
            "unknown_link.urdf",
            "",
            "unknown_link.urdf:7: unknown link `forearm`",
        ),
        (
            "malformed.urdf",
            "",
            "malformed.urdf: not a well-formed XML file",
        ),
        ("missing.urdf", "", "cannot read"),
        (
            "two_links.urdf",
            "locked: [j9]",
            "`j9` is not a joint of `tests/data/two_links.urdf`",
        ),
        ("two_links.urdf", "coordinates: [x]", "remove `coordinates`"),
        (
            "no_joint_moves.urdf",
            "",
            "no_joint_moves.urdf:2: no joint of the robot moves",
        ),
    ];
    for (file, extra, expected) in cases {
        let message = error_of(file, extra);
        assert!(message.contains(expected), "{file}: {message}");
    }
}

#[test]
fn urdf_is_exclusive_with_the_other_sources_of_the_mass_matrix() {
    let message = error_of("two_links.urdf", "mass: diag[1.0, 1.0]");
    assert!(message.contains("mutually exclusive"), "{message}");
}

/// An arm whose frames are turned by angles that are not right angles,
/// with a wrist and a finger (`locked` below) carrying masses. The lower
/// arm's own inertia is turned too, so that it is a full matrix with or
/// without the wrist merged into it.
const ARM: &str = r#"<robot name="arm">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.1 0 0.2" rpy="0.3 0 0"/><mass value="2"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial></link>
  <link name="lower"><inertial><origin xyz="0.05 0.1 0.2" rpy="0.4 0.3 0.2"/><mass value="1.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <joint name="shoulder" type="revolute"><origin xyz="0 0 0.3" rpy="0.3 0.2 0.1"/><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/></joint>
  <joint name="elbow" type="revolute"><origin xyz="0.4 0 0" rpy="1.5708 0 0.2618"/><parent link="upper"/><child link="lower"/><axis xyz="0 1 0"/></joint>
  WRIST
</robot>"#;

/// The wrist and the finger: two joints turned by constant angles.
const WRIST: &str = r#"<link name="hand"><inertial><origin xyz="0 0 0.05" rpy="0.1 0.2 0.3"/><mass value="0.7"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>
  <link name="tip"><inertial><origin xyz="0.02 0 0.03" rpy="0 0 0"/><mass value="0.1"/><inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial></link>
  <joint name="wrist" type="revolute"><origin xyz="0 0.3 0" rpy="0.2618 0 0.4"/><parent link="lower"/><child link="hand"/><axis xyz="1 0 0"/></joint>
  <joint name="finger" type="prismatic"><origin xyz="0 0 0.08" rpy="0.1 0.5 0.7"/><parent link="hand"/><child link="tip"/><axis xyz="0 0 1"/></joint>"#;

/// The expansion of the arm (with its wrist, locked, or without it) from a
/// file in the temporary directory.
fn arm(with_wrist: bool) -> syn::File {
    let text = ARM.replace("WRIST", if with_wrist { WRIST } else { "" });
    let path = std::env::temp_dir().join(format!(
        "constrained-arm-{with_wrist}-{}.urdf",
        std::process::id()
    ));
    std::fs::write(&path, text).expect("the temporary directory is writable");
    let locked = if with_wrist {
        "locked: [wrist, finger],"
    } else {
        ""
    };
    let source = format!(
        "struct Arm {{ urdf: {:?}, {locked} }}",
        path.display().to_string()
    );
    let tokens: proc_macro2::TokenStream = source.parse().expect("tokens");
    let expanded = expand(tokens).expect("the arm expands");
    let _ = std::fs::remove_file(&path);
    syn::parse2(expanded).expect("the expansion is Rust")
}

#[test]
fn constant_angles_are_folded_and_a_locked_subtree_is_a_constant_inertia() {
    use constrained_codegen::tools::op_count;
    use quote::ToTokens;
    let (locked, removed) = (arm(true), arm(false));
    // No sine or cosine of a constant: the argument of every one left
    // names a coordinate or a temporary.
    let text = locked.to_token_stream().to_string();
    let mut trig = 0;
    for (at, call) in text.match_indices("sin_cos (") {
        trig += 1;
        let argument = text[at + call.len()..]
            .split(')')
            .next()
            .unwrap_or_default();
        assert!(names_a_variable(argument), "sin_cos ({argument})");
    }
    for call in [". sin ()", ". cos ()"] {
        for (at, _) in text.match_indices(call) {
            trig += 1;
            let before = text[..at].trim_end();
            let receiver = before.rsplit([' ', '(']).next().unwrap_or_default();
            assert!(names_a_variable(receiver), "{receiver}{call}");
        }
    }
    assert!(trig > 0, "the joints' own sines are there");
    // The locked wrist and finger merge into the lower arm: its inertia is
    // a constant, and M costs what it costs without them.
    let m_locked = op_count::method(&locked, "mass_matrix").expect("M").total();
    let m_removed = op_count::method(&removed, "mass_matrix")
        .expect("M")
        .total();
    assert!(
        m_locked * 10 <= m_removed * 11,
        "M: {m_locked} operations with the wrist locked, {m_removed} without it"
    );
}

/// Whether generated code names a coordinate of the arm or a temporary.
fn names_a_variable(text: &str) -> bool {
    ["shoulder", "elbow", "__t"]
        .iter()
        .any(|name| text.contains(name))
}
