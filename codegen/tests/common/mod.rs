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
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("src/models exists") {
        let path = entry.expect("readable entry").path();
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
