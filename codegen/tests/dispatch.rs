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
