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
            "planar.urdf",
            "",
            "tests/data/planar.urdf:5: joint `slide` of type `planar` is not supported",
        ),
        (
            "mimic.urdf",
            "",
            "tests/data/mimic.urdf:9: joint `j2`: <mimic> is not supported",
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
