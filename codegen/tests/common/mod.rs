//! The reference models' macro invocations, read from their source files so
//! that snapshots pin exactly what the library compiles.

use proc_macro2::TokenStream;
use std::path::Path;

/// One `constrained_system! { ... }` invocation of the models.
pub struct Invocation {
    /// Name of the generated struct.
    pub name: String,
    /// The macro's input tokens.
    pub tokens: TokenStream,
}

/// Every invocation in `src/models/*.rs`, sorted by struct name.
pub fn model_invocations() -> Vec<Invocation> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/models");
    let paths = std::fs::read_dir(&dir)
        .expect("src/models exists")
        .map(|entry| entry.expect("readable entry").path());
    invocations_in(paths)
}

/// The models with gaps (`unilateral: [..]`), written once for the
/// examples in `examples/support/`, sorted by struct name.
#[allow(dead_code)] // used by the snapshots only
pub fn gap_model_invocations() -> Vec<Invocation> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/support");
    invocations_in(["rimless_wheel.rs", "compass_gait.rs"].map(|f| dir.join(f)))
}

/// The invocations in the given files under `examples/`.
#[allow(dead_code)] // used by the strategy test only
pub fn example_invocations(files: &[&str]) -> Vec<Invocation> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    invocations_in(files.iter().map(|f| dir.join(f)))
}

/// The `constrained_system!` invocations at the top level of `paths`.
fn invocations_in(paths: impl IntoIterator<Item = std::path::PathBuf>) -> Vec<Invocation> {
    let mut out = Vec::new();
    for path in paths {
        let source = std::fs::read_to_string(&path).expect("readable model source");
        let file = syn::parse_file(&source).expect("model source parses");
        for item in file.items {
            if let syn::Item::Macro(m) = item {
                if m.mac.path.is_ident("constrained_system") {
                    let tokens = m.mac.tokens.clone();
                    let input: constrained_codegen::parse::SystemInput =
                        syn::parse2(tokens.clone()).expect("model parses");
                    out.push(Invocation {
                        name: input.name.to_string(),
                        tokens,
                    });
                }
            }
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    out
}
