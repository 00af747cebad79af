//! The model's own values (`M`, `F`, `φ`, `φ̇`) and `(A, b)` as free
//! functions in a module of their own, each behind a method of the system
//! that forwards to it.
//!
//! Why: rustc places a generic method in the codegen unit of its type's
//! module, so every method of a system is optimized and compiled on one
//! thread; and an `#[inline]` method that another unit calls (the runtime's
//! dense solve calls `M`, `F`, `A`, `b`) is compiled again in that unit. A
//! large model's `M`, `F` and `A` were compiled twice. A generic free
//! function in a module of its own is compiled once, in a unit of its own,
//! beside the solve. The module holds only the functions, which name
//! nothing of the user's scope (the system's parameters are an argument):
//! a system defined inside a function body declares the module there too.

use super::body::Body;
use super::context::{Context, Inputs};
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use syn::Ident;

/// The operations from which a value is detached: a body this large is
/// not inlined into its callers anyway, so the call costs nothing, and
/// smaller ones stay methods that callers may inline.
pub(super) const DETACH_FROM: usize = 300;

/// Whether the value of `roots` is large: at least [`DETACH_FROM`]
/// operations.
pub(super) fn large(ctx: &Context, roots: &[Id]) -> bool {
    crate::expr::squares::operations(&ctx.eq.system.graph, roots) >= DETACH_FROM
}

/// A value method: the method on the system and, for a large one, the
/// function it forwards to.
pub(super) struct Detached {
    /// `pub fn name(&self, ..)`.
    pub(super) method: TokenStream,
    /// The module's `pub fn name<T>(.., __parameters: [T; P])`, if any.
    pub(super) function: Option<TokenStream>,
}

/// The module of the system's detached functions.
fn module(ctx: &Context) -> Ident {
    format_ident!("__constrained_{}", ctx.eq.system.name)
}

/// What a value method computes: `roots`, written by `value` from their
/// body.
pub(super) struct Value<'v> {
    /// The method's name.
    pub(super) name: TokenStream,
    /// Its documentation, one line of it per `\n`.
    pub(super) doc: &'v str,
    /// What it takes.
    pub(super) inputs: Inputs,
    /// Its type.
    pub(super) ret: TokenStream,
    /// The expressions it returns.
    pub(super) roots: &'v [Id],
}

/// The method `v`, its value written by `value` from the body of `v`'s
/// roots: in place when small, else in the module's function.
pub(super) fn value(
    ctx: &Context,
    v: &Value,
    value: impl FnOnce(&Body) -> TokenStream,
) -> Detached {
    value_of(ctx, v, Body::new(ctx.eq, v.roots), value)
}

/// [`value`] from a body built for it ([`Body::storing`]).
pub(super) fn value_of(
    ctx: &Context,
    v: &Value,
    body: Body,
    value: impl FnOnce(&Body) -> TokenStream,
) -> Detached {
    let (name, ret) = (&v.name, &v.ret);
    let (params, args) = (ctx.params(v.inputs), ctx.args(v.inputs));
    let (computed, function) = if large(ctx, v.roots) {
        let (preamble, value) = (body.detached_preamble(), value(&body));
        let module = module(ctx);
        let parameters = &ctx.eq.system.parameters;
        let count = Context::dim(parameters.len());
        let function = quote! {
            pub fn #name<T: ::constrained::nalgebra::RealField + Copy>(
                #params,
                __parameters: [T; #count],
            ) -> #ret {
                #preamble
                #value
            }
        };
        (
            quote!(#module::#name(#args, [#(self.#parameters),*])),
            Some(function),
        )
    } else {
        let (preamble, value) = (body.preamble(), value(&body));
        (quote!(#preamble #value), None)
    };
    let docs = v.doc.split('\n');
    let method = quote! {
        #(#[doc = #docs])*
        #[inline]
        pub fn #name(&self, #params) -> #ret {
            #computed
        }
    };
    Detached { method, function }
}

/// The module holding the detached functions, if any.
pub(super) fn functions(ctx: &Context, detached: &[Detached]) -> Option<TokenStream> {
    let functions: Vec<&TokenStream> = detached
        .iter()
        .filter_map(|d| d.function.as_ref())
        .collect();
    if functions.is_empty() {
        return None;
    }
    let module = module(ctx);
    let functions = super::hoist::literals(quote!(#(#functions)*));
    Some(quote! {
        #[doc(hidden)]
        #[allow(non_snake_case, unused_variables, clippy::all, clippy::pedantic)]
        mod #module {
            #functions
        }
    })
}

#[cfg(test)]
mod tests {
    use crate::tools::fixtures::{panda, planar_chain};

    /// The detached functions of `source`'s expansion, by name.
    fn detached(source: &str) -> Vec<String> {
        let expanded = crate::expand(source.parse().expect("tokens")).expect("expands");
        let file: syn::File = syn::parse2(expanded).expect("Rust");
        crate::tools::op_count::detached_functions(&file)
            .map(|f| f.sig.ident.to_string())
            .collect()
    }

    /// A six-joint Panda's `M` (past `DETACH_FROM` operations) writes each
    /// of its 36 entries into the returned local once, as soon as it is
    /// known ([`crate::emit::body::Body::storing`]): 36 stores, no two into
    /// one place, and the local is the value.
    #[test]
    fn a_large_mass_matrix_stores_each_entry_once() {
        let expanded = crate::expand(panda("Arm", 6).parse().expect("tokens")).expect("expands");
        let file: syn::File = syn::parse2(expanded).expect("Rust");
        let m = crate::tools::op_count::detached_functions(&file)
            .find(|f| f.sig.ident == "mass_matrix")
            .expect("detached");
        let mut places = std::collections::HashSet::new();
        for stmt in &m.block.stmts {
            if let syn::Stmt::Expr(syn::Expr::Assign(a), _) = stmt {
                let place = quote::ToTokens::to_token_stream(&a.left).to_string();
                assert!(place.starts_with("__out0 . data . 0 ["), "{place}");
                assert!(places.insert(place.clone()), "{place} stored twice");
            }
        }
        assert_eq!(places.len(), 36);
        let tail = m
            .block
            .stmts
            .last()
            .map(|s| quote::ToTokens::to_token_stream(s).to_string());
        assert_eq!(tail.as_deref(), Some("__out0"));
    }

    /// A six-joint Panda's `M` and `F` are computed in the module (each
    /// past `DETACH_FROM` operations); a two-link chain's values stay
    /// methods, and it has no module.
    #[test]
    fn large_values_are_detached_and_small_ones_stay_methods() {
        let arm = detached(&panda("Arm", 6));
        assert!(arm.contains(&"mass_matrix".to_string()), "{arm:?}");
        assert!(arm.contains(&"forces".to_string()), "{arm:?}");
        assert_eq!(detached(&planar_chain("Chain", 2)), Vec::<String>::new());
    }
}
