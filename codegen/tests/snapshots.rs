//! Snapshots of every reference model (and of the examples' models with
//! gaps, `examples/support/`): the formatted expansion (what the
//! compiler sees) and the derivation (what a reviewer reads). A change in the
//! symbolic core shows up here as a diff of generated code and mathematics.
//! Review changes with `cargo insta review` (or read the `.snap.new` files).

mod common;

#[test]
fn expansions_and_derivations() {
    let mut models = common::model_invocations();
    assert!(
        models.len() >= 8,
        "expected every reference model, found {}",
        models.len()
    );
    // And the models with gaps, for their `SYMBOLIC_GAPS` and derivation.
    models.extend(common::gap_model_invocations());
    // Every snapshot is checked even after a mismatch, so that one run writes
    // every `.snap.new` to review.
    let mut failed = Vec::new();
    for model in models {
        let expanded = constrained_codegen::expand(model.tokens.clone())
            .unwrap_or_else(|e| panic!("{} fails to expand: {e}", model.name));
        let file: syn::File = syn::parse2(expanded).expect("expansion is valid Rust");
        let equations = constrained_codegen::analyse(model.tokens).expect("analyses");
        let snapshots = [
            (
                format!("{}_expansion", model.name),
                prettyplease::unparse(&file),
            ),
            (
                format!("{}_derivation", model.name),
                constrained_codegen::emit::derivation::text(&equations, &equations.partition),
            ),
        ];
        for (name, text) in snapshots {
            let checked = std::panic::catch_unwind(|| insta::assert_snapshot!(name.clone(), text));
            if checked.is_err() {
                failed.push(name);
            }
        }
    }
    assert!(failed.is_empty(), "snapshots differ: {failed:?}");
}
