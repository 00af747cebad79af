//! Snapshots of every reference model: the formatted expansion (what the
//! compiler sees) and the derivation (what a reviewer reads). A change in the
//! symbolic core shows up here as a diff of generated code and mathematics.
//! Review changes with `cargo insta review` (or read the `.snap.new` files).

mod common;

#[test]
fn expansions_and_derivations() {
    let models = common::model_invocations();
    assert!(
        models.len() >= 8,
        "expected every reference model, found {}",
        models.len()
    );
    // Every model is checked even after a mismatch, so that one run writes
    // every `.snap.new` to review.
    let failed: Vec<String> = models
        .into_iter()
        .filter_map(|model| {
            let name = model.name.clone();
            std::panic::catch_unwind(move || snapshot(model))
                .err()
                .map(|_| name)
        })
        .collect();
    assert!(failed.is_empty(), "snapshots differ for: {failed:?}");
}

fn snapshot(model: common::Invocation) {
    let expanded = constrained_codegen::expand(model.tokens.clone())
        .unwrap_or_else(|e| panic!("{} fails to expand: {e}", model.name));
    let file: syn::File = syn::parse2(expanded).expect("expansion is valid Rust");
    insta::assert_snapshot!(
        format!("{}_expansion", model.name),
        prettyplease::unparse(&file)
    );
    let equations = constrained_codegen::analyse(model.tokens).expect("analyses");
    insta::assert_snapshot!(
        format!("{}_derivation", model.name),
        constrained_codegen::derivation::text(&equations)
    );
}
