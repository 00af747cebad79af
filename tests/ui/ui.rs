//! Compile-fail tests: every kind of bad input is an error spanned on the
//! offending tokens, and one input's errors are reported together. Each
//! `.stderr` is reviewed; regenerate with `TRYBUILD=overwrite` and read the diff.

#[test]
fn errors() {
    trybuild::TestCases::new().compile_fail("tests/ui/errors/*.rs");
}
