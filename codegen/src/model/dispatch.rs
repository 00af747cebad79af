//! The `dispatch` section: the instruction-set extensions a system's large
//! methods are also compiled for, each copy chosen at run time on a CPU
//! that has it,
//!
//! ```text
//! dispatch: [avx]
//! ```
//!
//! Any system may ask; `crate::emit` writes the copies and the choice.

use super::ctxt::Errors;
use crate::parse::List;
use syn::ext::IdentExt;
use syn::Ident;

/// An instruction-set extension the large methods are also compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extension {
    /// x86-64's AVX: the same IEEE operations as SSE2, in three-operand
    /// (VEX) encodings and 256-bit registers, so the copy's answers are
    /// the baseline's bit for bit.
    Avx,
}

impl Extension {
    /// Every extension, with its name in the section.
    const ALL: [(&'static str, Extension); 1] = [("avx", Extension::Avx)];
}

/// The extensions `list` names, in its order; errors recorded for every
/// other name and every repeated one.
pub(super) fn extensions(list: &List<Ident>, errors: &mut Errors) -> Vec<Extension> {
    let mut seen: Vec<Extension> = Vec::new();
    for name in &list.items {
        let text = name.unraw().to_string();
        match Extension::ALL.iter().find(|(n, _)| *n == text) {
            None => {
                let known: Vec<String> = Extension::ALL
                    .iter()
                    .map(|(n, _)| format!("`{n}`"))
                    .collect();
                errors.spanned(
                    name,
                    format!(
                        "no dispatch on `{text}`: expected one of {}",
                        known.join(", ")
                    ),
                );
            }
            Some((_, e)) if seen.contains(e) => {
                errors.spanned(name, format!("`{text}` is named twice"));
            }
            Some((_, e)) => seen.push(*e),
        }
    }
    seen
}
