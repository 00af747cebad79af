//! Compile-fail tests: every kind of bad input is an error spanned on the
//! offending tokens, and one input's errors are reported together. Each
//! `.stderr` is reviewed; regenerate with `TRYBUILD=overwrite` and read the diff.

#[test]
fn errors() {
    // Paths are relative to this package (tests/ui), as in the `.stderr`.
    trybuild::TestCases::new().compile_fail("errors/*.rs");
}
