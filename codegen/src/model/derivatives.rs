//! The `derivatives` section: the methods whose exact derivatives are
//! generated beside them, each asked for by name so that a system that
//! does not ask compiles none of their code,
//!
//! ```text
//! derivatives: [inverse_dynamics]
//! ```
//!
//! `inverse_dynamics` gives `inverse_dynamics_jacobian`, `(∂τ/∂q, ∂τ/∂q̇)`
//! (`crate::equations`). With `bodies` or `urdf` only (`super::source`
//! says so).

use super::lower::Lowerer;
use crate::parse::List;
use syn::ext::IdentExt;
use syn::Ident;

/// The methods the section may name.
const DIFFERENTIABLE: &[&str] = &["inverse_dynamics"];

impl Lowerer<'_> {
    /// Whether `list` asks for the derivatives of `inverse_dynamics`;
    /// errors recorded for every other name and every repeated one.
    pub(super) fn derivatives_section(&mut self, list: &List<Ident>) -> bool {
        let mut seen: Vec<String> = Vec::new();
        for name in &list.items {
            let text = name.unraw().to_string();
            if !DIFFERENTIABLE.contains(&text.as_str()) {
                let known: Vec<String> = DIFFERENTIABLE.iter().map(|d| format!("`{d}`")).collect();
                self.errors.spanned(
                    name,
                    format!(
                        "no derivatives of `{text}` are generated: expected one of {}",
                        known.join(", ")
                    ),
                );
            } else if seen.contains(&text) {
                self.errors
                    .spanned(name, format!("`{text}` is named twice"));
            }
            seen.push(text);
        }
        seen.iter().any(|s| s == "inverse_dynamics")
    }
}
