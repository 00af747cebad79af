//! The refusals of the `bodies` section and of the sections beside it
//! (`right_angles_within`, `derivatives`, `dispatch`), each spanned and
//! saying why.

use constrained_codegen::expand;

fn errors_of(bodies: &str) -> String {
    let source = format!("struct R {{ parameters: [m], bodies: [{bodies}] }}");
    let tokens: proc_macro2::TokenStream = source.parse().expect("tokens");
    match expand(tokens) {
        Ok(_) => panic!("accepted: {bodies}"),
        Err(e) => e
            .into_iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n"),
    }
}

#[test]
fn bodies_errors_say_why() {
    let ok = "joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0";
    let cases = [
        (format!("a {{ {ok}, parent: b }}"), "unknown parent `b`"),
        ("a { mass: 1.0 }".to_string(), "body `a` has no `joint`"),
        (
            format!("a {{ {ok}, colour: 1.0 }}"),
            "unknown field `colour`",
        ),
        (
            format!("a {{ {ok} }}, a {{ joint: revolute(q2, [1.0, 0.0, 0.0]) }}"),
            "body `a`: declared twice",
        ),
        (format!("world {{ {ok} }}"), "`world` is the fixed frame"),
        (
            "a { joint: revolute(q1, [0.0, 0.0, 0.0]) }".to_string(),
            "the joint's axis is zero",
        ),
        (
            "a { joint: cylindrical(q1, [0.0, 0.0, 1.0]) }".to_string(),
            "expected `revolute(q, axis)`",
        ),
        (
            "a { joint: spherical(q1) }".to_string(),
            "expected `spherical(qw, qx, qy, qz)`",
        ),
        (
            "a { joint: spherical(w, i, j, 1.0), mass: 1.0 }".to_string(),
            "expected `spherical(qw, qx, qy, qz)`",
        ),
        (
            "a { joint: revolute(q1, [0.0, 1.0]) }".to_string(),
            "the axis has 3 entries",
        ),
        (
            format!("a {{ {ok}, inertia: [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }}"),
            "`inertia` is not symmetric",
        ),
        (
            "a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: q1 }".to_string(),
            "not coordinates, velocities or `t`",
        ),
        (
            format!("a {{ {ok}, xyz: [t, 0.0, 0.0] }}"),
            "not coordinates, velocities or `t`",
        ),
        (
            "a { joint: free(x, y, z), mass: 1.0 }".to_string(),
            "expected `free(x, y, z, qw, qx, qy, qz)`",
        ),
        (
            "a { joint: free(x, y, z, w, i, j, 1.0), mass: 1.0 }".to_string(),
            "expected `free(x, y, z, qw, qx, qy, qz)`",
        ),
        (
            "a { joint: free(x, y, z, w, i, j, k), mass: 1.0 },              b { parent: a, joint: free(x2, y2, z2, w2, i2, j2, k2), mass: x }"
                .to_string(),
            "not coordinates, velocities or `t`",
        ),
    ];
    for (bodies, expected) in cases {
        let message = errors_of(&bodies);
        assert!(message.contains(expected), "{bodies}: {message}");
    }
}

#[test]
fn points_need_known_bodies_and_three_entries() {
    let source = "struct R { bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0 }], \
                  forces: [position(b, [0.0, 0.0, 0.0]).x + position(a, [1.0, 0.0]).y + position(a, [1.0, 0.0, 0.0]).w] }";
    let tokens: proc_macro2::TokenStream = source.parse().expect("tokens");
    let message = match expand(tokens) {
        Ok(_) => panic!("accepted"),
        Err(e) => e
            .into_iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n"),
    };
    for expected in [
        "unknown body `b`",
        "the point has 3 entries",
        "`.x`, `.y` or `.z`",
    ] {
        assert!(message.contains(expected), "{message}");
    }
    let source =
        "struct R { coordinates: [x], mass: diag[1.0], forces: [position(a, [0.0, 0.0, 0.0]).x] }";
    let message = expand(source.parse().expect("tokens"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        message.contains("need a `bodies` or `urdf` section"),
        "{message}"
    );
    // Every function of bodies from one table: its usage in the message.
    let body = "bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0 }]";
    for (force, expected) in [
        (
            "orientation(a).x",
            "`orientation(body)` is one side of a lock",
        ),
        (
            "spin(a).x",
            "expected `position(body, [x, y, z])`, `velocity(body, [x, y, z])`",
        ),
        (
            "angular_velocity(a, a).z",
            "expected `angular_velocity(body)`",
        ),
    ] {
        let source = format!("struct R {{ {body}, forces: [{force}] }}");
        let message = expand(source.parse().expect("tokens"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(message.contains(expected), "{force}: {message}");
    }
}

/// The `frames` section's refusals, each pointing at its token: the
/// message and the column where the error starts.
#[test]
fn frames_errors_point_at_their_tokens() {
    let arm = "bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0 }]";
    let cases = [
        (
            "tip { body: b }",
            "b }",
            "unknown body `b`: expected one of `a`",
        ),
        (
            "tip { body: a, colour: 1.0 }",
            "colour",
            "unknown field `colour` of a frame",
        ),
        (
            "tip { xyz: [0.0, 0.0, 0.1] }",
            "{",
            "frame `tip` needs `body",
        ),
        (
            "tip { body: a }, tip { body: a }",
            "tip { body: a }",
            "duplicate frame `tip`",
        ),
        (
            "center_of_mass { body: a }",
            "center_of_mass",
            "the name of a generated method",
        ),
        (
            "tip { body: a, xyz: [q1, 0.0, 0.0] }",
            "q1",
            "not coordinates, velocities or `t`",
        ),
        (
            "tip { body: a, inertia: diag[1.0, 1.0, 1.0] }",
            "inertia",
            "a frame has no inertia",
        ),
        ("tip { body: a.b }", "a.b", "expected the name of a body"),
    ];
    for (frames, at, why) in cases {
        let source = format!("struct R {{ {arm}, frames: [{frames}] }}");
        // The duplicate is the second frame: its name's column.
        let column = match why {
            "duplicate frame `tip`" => source.rfind(at),
            _ => source
                .find(&format!("frames: [{frames}"))
                .and_then(|f| source[f..].find(at).map(|i| f + i)),
        };
        assert_error_at_column(&source, column, why);
    }
    let source = "struct R { coordinates: [x], mass: diag[1.0], frames: [] }";
    let message = expand(source.parse().expect("tokens"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        message.contains("`frames` applies to `bodies` or `urdf` only"),
        "{message}"
    );
}

#[test]
fn right_angles_within_needs_urdf_and_a_small_tolerance() {
    let message_of = |source: &str| {
        expand(source.parse().expect("tokens"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let source = "struct R { parameters: [m], bodies: [b { joint: revolute(q, [0.0, 0.0, 1.0]), mass: m }], right_angles_within: 1e-6 }";
    let message = message_of(source);
    assert!(
        message.contains("`right_angles_within` applies to `urdf` only"),
        "{message}"
    );
    // The tolerance is checked before the file is read.
    let source = r#"struct R { urdf: "no/such/file.urdf", right_angles_within: 0.5 }"#;
    let message = message_of(source);
    assert!(
        message.contains("`right_angles_within` is a tolerance in radians in (0, 0.01], not 0.5"),
        "{message}"
    );
}

/// The `derivatives` section's refusals: a method without generated
/// derivatives and a repeated name, each at its name, and the section
/// without bodies.
#[test]
fn derivatives_errors_point_at_their_names() {
    let arm = "bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0 }]";
    let cases = [
        (
            "acceleration",
            "acceleration",
            "no derivatives of `acceleration` are generated: expected one of `inverse_dynamics`",
        ),
        (
            "inverse_dynamics, inverse_dynamics",
            "inverse_dynamics]",
            "`inverse_dynamics` is named twice",
        ),
    ];
    for (names, at, why) in cases {
        let source = format!("struct R {{ {arm}, derivatives: [{names}] }}");
        assert_error_at(&source, at, why);
    }
    let source = "struct R { coordinates: [x], mass: diag[1.0], derivatives: [inverse_dynamics] }";
    let message = expand(source.parse().expect("tokens"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        message.contains("`derivatives` applies to `bodies` or `urdf` only"),
        "{message}"
    );
    // Asked for, the method is generated; not asked for, it is not.
    let arm =
        "bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0, com: [0.3, 0.0, 0.0] }]";
    let with = format!("struct R {{ {arm}, derivatives: [inverse_dynamics] }}");
    let without = format!("struct R {{ {arm} }}");
    let has = |s: &str| {
        let expanded = expand(s.parse().expect("tokens")).expect("expands");
        expanded
            .to_string()
            .contains("fn inverse_dynamics_jacobian")
    };
    assert!(has(&with) && !has(&without));
}

/// Expanding `source` fails with an error saying `why`, spanned at the
/// last `at` of the source (one line: its column is its offset).
fn assert_error_at(source: &str, at: &str, why: &str) {
    assert_error_at_column(source, source.rfind(at), why);
}

/// Expanding the one-line `source` fails with an error saying `why`,
/// spanned at `column`.
fn assert_error_at_column(source: &str, column: Option<usize>, why: &str) {
    let tokens: proc_macro2::TokenStream = source.parse().expect("tokens");
    let Err(errors) = expand(tokens) else {
        panic!("accepted: {source}")
    };
    let hit = errors.into_iter().find(|e| e.to_string().contains(why));
    let Some(e) = hit else {
        panic!("no error saying {why:?} for {source}")
    };
    assert_eq!(
        Some(e.span().start().column),
        column,
        "{why}: spanned at the wrong token in {source}"
    );
}

/// The `dispatch` section's refusals, each at its name: an extension it
/// does not know and a repeated one. Any system may ask, not only a tree
/// (the copies and their answers are tested in `tests/dispatch.rs`).
#[test]
fn dispatch_errors_point_at_their_names() {
    let particle = "coordinates: [x], mass: diag[1.0]";
    let cases = [
        (
            "avx512",
            "avx512",
            "no dispatch on `avx512`: expected one of `avx`",
        ),
        ("avx, avx", "avx]", "`avx` is named twice"),
    ];
    for (names, at, why) in cases {
        let source = format!("struct P {{ {particle}, dispatch: [{names}] }}");
        assert_error_at(&source, at, why);
    }
    let source = format!("struct P {{ {particle}, dispatch: [avx] }}");
    assert!(expand(source.parse().expect("tokens")).is_ok());
}
