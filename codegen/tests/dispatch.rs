//! The `dispatch` section's refusals (the copies and their answers are
//! tested where they compile, in `tests/dispatch.rs`).

use constrained_codegen::expand;

/// The section's refusals, each at its name: an extension it does not
/// know and a repeated one. Any system may ask, not only a tree.
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
        let Err(errors) = expand(source.parse().expect("tokens")) else {
            panic!("accepted: {names}")
        };
        let hit = errors.into_iter().find(|e| e.to_string().contains(why));
        let Some(e) = hit else {
            panic!("no error saying {why:?} for {names}")
        };
        assert_eq!(
            Some(e.span().start().column),
            source.rfind(at),
            "{why}: spanned at the wrong token in {source}"
        );
    }
    let source = format!("struct P {{ {particle}, dispatch: [avx] }}");
    assert!(expand(source.parse().expect("tokens")).is_ok());
}

/// A system without a large function expands as it does without the
/// section: no copy, no check.
#[test]
fn a_small_system_is_unchanged_by_the_section() {
    let arm = "bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0, com: [0.3, 0.0, 0.0] }], derivatives: [inverse_dynamics]";
    let expanded = |extra: &str| {
        let source = format!("struct R {{ {arm}{extra} }}");
        expand(source.parse().expect("tokens"))
            .expect("expands")
            .to_string()
    };
    assert_eq!(expanded(", dispatch: [avx]"), expanded(""));
}
