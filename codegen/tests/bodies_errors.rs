//! The `bodies` section's refusals, each spanned and saying why.

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
