//! `dispatch: [avx]`: each large function of the generated code also
//! compiled with the extension enabled, and the copy chosen at run time.
//!
//! A token pass over what the other passes emitted, like `hoist`. A large
//! function `f` keeps its signature and its body, and first asks the
//! runtime whether the CPU has the extension; if it has, `f` returns what
//! its copy `__avx_f` returns. The copy is the same body under
//! `#[target_feature(enable = "avx")]`, and so is every function item
//! nested in it (a nested item does not inherit its parent's features).
//! A method of a trait impl cannot carry a target feature: its copy is a
//! method of an inherent impl with the trait impl's generics. Both the
//! check and the copies exist only on x86-64 built without AVX: built with
//! it, the baseline is the copy. The runtime reads the CPU once
//! (`constrained::__private::has_avx`); a call then costs one load and one
//! branch.
//!
//! The copy's arithmetic is the baseline's: AVX adds encodings (three
//! operands, so fewer register copies) and wider registers, not other
//! roundings, and no FMA is enabled. The gain is in code size: the largest
//! bodies hold more values than registers, and the spills and copies of
//! the two-operand SSE2 encodings make them longer than a 32 KiB L1i.
//!
//! FMA is not a further extension. Fusing products into the sums they
//! feed speeds the large solves, whose updates accumulate into values
//! read once, but slows the recursions of the derivatives, which reuse
//! their values: a multiply-add overwrites its addend, so more values are
//! copied and spilled and the code grows; folding a whole sum into one
//! chain of multiply-adds also lengthens its dependency chain (a
//! multiply-add waits longer than an add). And its answers would not be
//! the baseline's bit for bit, which the copies promise.

use crate::model::dispatch::Extension;
use proc_macro2::{TokenStream, TokenTree};
use quote::{format_ident, quote};
use syn::visit_mut::VisitMut;
use syn::{
    Attribute, Block, FnArg, Generics, ImplItem, ImplItemFn, Item, ItemFn, Pat, Signature,
    Visibility,
};

/// The size, in tokens, from which a function is copied: about 1,300
/// operations, 20 to 40 KB of SSE2 code. Measured on the benchmarks'
/// robots, a copy pays where the baseline's code outgrows a 32 KiB L1i
/// (the Panda's ∂τ, 59 KB, runs 26 % faster; the G1's `M`, 35 KB, 13 %)
/// and not below it (the Panda's solve, 8,300 tokens; TALOS's `M`, 32
/// KB): there it would cost compile time for nothing.
const LARGE: usize = 10_000;

/// The inherent methods `methods` (a sequence of `fn` items), each large
/// one with its copies.
pub(super) fn methods(methods: TokenStream, extensions: &[Extension]) -> TokenStream {
    if extensions.is_empty() {
        return methods;
    }
    let Ok(block) = syn::parse2::<syn::ItemImpl>(quote!(impl __Methods { #methods })) else {
        return methods;
    };
    let mut out = TokenStream::new();
    let mut copied = false;
    for item in block.items {
        match item {
            ImplItem::Fn(f) => match with_copy(&f, true) {
                Some((wrapper, copy)) => {
                    copied = true;
                    out.extend(quote!(#wrapper #copy));
                }
                None => out.extend(quote!(#f)),
            },
            other => out.extend(quote!(#other)),
        }
    }
    // Nothing large: the tokens as they came, not as syn prints them.
    if copied {
        out
    } else {
        methods
    }
}

/// The items `items` (impls, modules, functions), each large function
/// with its copies.
pub(super) fn items(items: TokenStream, extensions: &[Extension]) -> TokenStream {
    if extensions.is_empty() {
        return items;
    }
    let Ok(file) = syn::parse2::<syn::File>(items.clone()) else {
        return items;
    };
    let mut out = TokenStream::new();
    let mut copied = false;
    for item in file.items {
        let (tokens, any) = item_with_copies(item);
        out.extend(tokens);
        copied |= any;
    }
    // Nothing large: the tokens as they came, not as syn prints them.
    if copied {
        out
    } else {
        items
    }
}

/// One item, its large functions (or methods, or a module's functions)
/// with their copies; and whether it has any.
fn item_with_copies(item: Item) -> (TokenStream, bool) {
    match item {
        Item::Fn(f) => match with_copy(&f, false) {
            Some((wrapper, copy)) => (quote!(#wrapper #copy), true),
            None => (quote!(#f), false),
        },
        Item::Mod(mut m) => {
            let Some((_, content)) = m.content.take() else {
                return (quote!(#m), false);
            };
            let mut inner = TokenStream::new();
            let mut copied = false;
            for item in content {
                let (tokens, any) = item_with_copies(item);
                inner.extend(tokens);
                copied |= any;
            }
            let (attrs, vis, ident) = (&m.attrs, &m.vis, &m.ident);
            (quote!(#(#attrs)* #vis mod #ident { #inner }), copied)
        }
        Item::Impl(mut imp) => {
            let mut copies = Vec::new();
            for item in &mut imp.items {
                if let ImplItem::Fn(f) = item {
                    if let Some((wrapper, copy)) = with_copy(f, true) {
                        *f = wrapper;
                        copies.push(copy);
                    }
                }
            }
            let copied = !copies.is_empty();
            if !copied || imp.trait_.is_none() {
                imp.items.extend(copies.into_iter().map(ImplItem::Fn));
                return (quote!(#imp), copied);
            }
            // A trait's method cannot carry a target feature: its copy is
            // an inherent method of the same type, under the same bounds.
            let (generics, self_ty) = (&imp.generics, &imp.self_ty);
            let where_clause = &generics.where_clause;
            let attrs = imp.attrs.iter().filter(|a| a.path().is_ident("allow"));
            let tokens = quote! {
                #imp
                #(#attrs)*
                impl #generics #self_ty #where_clause {
                    #(#copies)*
                }
            };
            (tokens, true)
        }
        other => (quote!(#other), false),
    }
}

/// The parts of a function item the pass reads and rewrites.
trait FunctionItem: Clone {
    fn parts(
        &mut self,
    ) -> (
        &mut Vec<Attribute>,
        &mut Visibility,
        &mut Signature,
        &mut Block,
    );
}

/// [`FunctionItem`] for a method and for a free function, whose fields
/// are named alike.
macro_rules! function_item {
    ($($item:ty),*) => {$(
        impl FunctionItem for $item {
            fn parts(
                &mut self,
            ) -> (&mut Vec<Attribute>, &mut Visibility, &mut Signature, &mut Block) {
                (&mut self.attrs, &mut self.vis, &mut self.sig, &mut self.block)
            }
        }
    )*};
}

function_item!(ImplItemFn, ItemFn);

/// A large function's wrapper (its signature, the check, its body) and
/// its copy, called as `Self::__avx_f` from a method; `None` for a small
/// one or one whose arguments cannot be passed on.
fn with_copy<F: FunctionItem>(f: &F, method: bool) -> Option<(F, F)> {
    let mut wrapper = f.clone();
    let (_, _, sig, block) = wrapper.parts();
    let name = copy_ident(sig)?;
    if !large(block) {
        return None;
    }
    let callee = if method {
        quote!(Self::#name)
    } else {
        quote!(#name)
    };
    let checked = checked(forwarded(sig, callee)?, block);
    *block = checked;
    let mut copy = f.clone();
    let (attrs, vis, sig, block) = copy.parts();
    *vis = Visibility::Inherited;
    sig.ident = name;
    *attrs = copy_attributes(attrs);
    featured(block);
    Some((wrapper, copy))
}

/// The copy's name, or `None` where the signature cannot carry a target
/// feature (`const`, `unsafe`, `async`, `extern`).
fn copy_ident(sig: &Signature) -> Option<syn::Ident> {
    let plain = sig.constness.is_none()
        && sig.unsafety.is_none()
        && sig.asyncness.is_none()
        && sig.abi.is_none();
    plain.then(|| format_ident!("__avx_{}", sig.ident))
}

/// Whether `block` is worth a copy ([`LARGE`]).
fn large(block: &Block) -> bool {
    fn count(tokens: TokenStream, total: &mut usize) {
        for t in tokens {
            *total += 1;
            if let TokenTree::Group(g) = t {
                count(g.stream(), total);
            }
        }
    }
    let mut total = 0;
    count(quote!(#block), &mut total);
    total >= LARGE
}

/// The call of `callee` with the signature's own receiver, generics and
/// arguments; `None` where an argument is a pattern rather than a name,
/// or an `impl Trait` forbids naming the generics.
fn forwarded(sig: &Signature, callee: TokenStream) -> Option<TokenStream> {
    let mut args = Vec::new();
    for input in &sig.inputs {
        match input {
            FnArg::Receiver(_) => args.push(quote!(self)),
            FnArg::Typed(t) => match &*t.pat {
                Pat::Ident(p) if p.subpat.is_none() => {
                    if matches!(&*t.ty, syn::Type::ImplTrait(_)) {
                        return None;
                    }
                    let name = &p.ident;
                    args.push(quote!(#name));
                }
                _ => return None,
            },
        }
    }
    let generics = turbofish(&sig.generics);
    Some(quote!(#callee #generics (#(#args),*)))
}

/// `::<A, B, N>` for the type and const parameters (lifetimes are
/// inferred), or nothing.
fn turbofish(generics: &Generics) -> TokenStream {
    let names: Vec<&syn::Ident> = generics
        .params
        .iter()
        .filter_map(|p| match p {
            syn::GenericParam::Type(t) => Some(&t.ident),
            syn::GenericParam::Const(c) => Some(&c.ident),
            syn::GenericParam::Lifetime(_) => None,
        })
        .collect();
    if names.is_empty() {
        TokenStream::new()
    } else {
        quote!(::<#(#names),*>)
    }
}

/// The configurations where the copies exist: x86-64 with its SSE2
/// registers (not a soft-float target such as a kernel's), built without
/// AVX.
fn where_copied() -> TokenStream {
    quote!(#[cfg(all(
        target_arch = "x86_64",
        target_feature = "sse2",
        not(target_feature = "avx")
    ))])
}

/// `body`, first returning `call` where the CPU has AVX.
fn checked(call: TokenStream, body: &Block) -> Block {
    let cfg = where_copied();
    let stmts = &body.stmts;
    syn::parse_quote! {{
        #cfg
        {
            if ::constrained::__private::has_avx() {
                // SAFETY: the CPU runs AVX and the system saves its
                // registers, the one feature the copy is compiled with.
                return unsafe { #call };
            }
        }
        #(#stmts)*
    }}
}

/// The copy's attributes: the original's but its docs and `inline`, then
/// hidden, only where copied, with the feature (`inline(always)` may not
/// carry one).
fn copy_attributes(attrs: &[Attribute]) -> Vec<Attribute> {
    let cfg = where_copied();
    let mut kept: Vec<Attribute> = attrs
        .iter()
        .filter(|a| !a.path().is_ident("doc") && !a.path().is_ident("inline"))
        .cloned()
        .collect();
    kept.extend([
        syn::parse_quote!(#[doc(hidden)]),
        syn::parse_quote!(#cfg),
        syn::parse_quote!(#[target_feature(enable = "avx")]),
    ]);
    kept
}

/// Every function item nested in `block` compiled with the feature too.
fn featured(block: &mut Block) {
    struct Nested;
    impl VisitMut for Nested {
        fn visit_item_fn_mut(&mut self, f: &mut ItemFn) {
            f.attrs.retain(|a| !a.path().is_ident("inline"));
            f.attrs
                .push(syn::parse_quote!(#[target_feature(enable = "avx")]));
            syn::visit_mut::visit_item_fn_mut(self, f);
        }
    }
    Nested.visit_block_mut(block);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body of `n` statements of eight tokens, large enough for a copy
    /// from 1,250.
    fn body(n: usize) -> TokenStream {
        let statements = (0..n).map(|i| {
            let x = format_ident!("x{i}");
            quote!(let #x = a * b + c;)
        });
        quote!(#(#statements)*)
    }

    #[test]
    fn a_large_method_calls_its_copy_where_the_cpu_has_avx() {
        let b = body(2_000);
        let small = body(10);
        let input = quote! {
            /// Docs.
            #[inline(always)]
            pub fn big<__F: Finish<T, 2>>(&self, q: &V, t: T) -> __F::Output {
                fn nested<T>(x: T) -> T { x }
                #b
                nested(t)
            }
            pub fn small(&self, q: &V) -> T { #small q }
        };
        let out = methods(input, &[Extension::Avx]).to_string();
        let wrapper = "if :: constrained :: __private :: has_avx () { return unsafe { Self :: __avx_big :: < __F > (self , q , t) } ; }";
        assert!(out.contains(wrapper), "{out}");
        assert!(out.contains("fn __avx_big < __F : Finish < T , 2 > > (& self , q : & V , t : T)"));
        // The copy is hidden, not inline(always), and its nested function
        // carries the feature too.
        let copy = &out[out.find("# [doc (hidden)]").expect("a hidden copy")..];
        assert!(copy.contains("# [target_feature (enable = \"avx\")] fn __avx_big"));
        assert!(copy.contains("# [target_feature (enable = \"avx\")] fn nested"));
        assert!(!copy.contains("inline (always)"));
        assert_eq!(
            out.matches("has_avx").count(),
            1,
            "the small method is left alone"
        );
        assert!(!out.contains("__avx_small"));
    }

    #[test]
    fn a_trait_method_copies_into_an_inherent_impl() {
        let b = body(2_000);
        let input = quote! {
            #[allow(non_snake_case)]
            impl<T: RealField + Copy> Tangent<T, 2> for Model<T> {
                fn tangent_rhs(&self, q: &V, out: &mut M) { #b }
            }
        };
        let out = items(input, &[Extension::Avx]).to_string();
        assert!(out.contains("Self :: __avx_tangent_rhs (self , q , out)"));
        assert!(
            out.contains("# [allow (non_snake_case)] impl < T : RealField + Copy > Model < T > {")
        );
    }

    #[test]
    fn without_extensions_the_tokens_are_untouched() {
        let b = body(2_000);
        let input = quote!(fn big(&self) { #b });
        assert_eq!(methods(input.clone(), &[]).to_string(), input.to_string());
    }
}
