//! Token streams assembled by moving their parts, not by interpolating them
//! into `quote!`, which copies every token of a part again (and again at
//! each level of nesting: a sum inside a product inside a sum…), a cost
//! that grows with the depth of the expressions.

use proc_macro2::{Delimiter, Group, TokenStream, TokenTree};
use quote::quote;

/// The parts one after the other.
pub(crate) fn concat(parts: impl IntoIterator<Item = TokenStream>) -> TokenStream {
    let mut out = TokenStream::new();
    for part in parts {
        out.extend(part);
    }
    out
}

/// `(tokens)`.
pub(crate) fn parenthesized(tokens: TokenStream) -> TokenStream {
    TokenTree::Group(Group::new(Delimiter::Parenthesis, tokens)).into()
}

/// `{ tokens }`.
pub(crate) fn braced(tokens: TokenStream) -> TokenStream {
    TokenTree::Group(Group::new(Delimiter::Brace, tokens)).into()
}

/// `f₁ * f₂ * …`, `None` for no factors.
pub(crate) fn join_product(factors: Vec<TokenStream>) -> Option<TokenStream> {
    let mut factors = factors.into_iter();
    let mut out = factors.next()?;
    for f in factors {
        out.extend(quote!(*));
        out.extend(f);
    }
    Some(out)
}

/// `t₁ + t₂ − t₃ …` of signed terms (`true`: subtracted; a first term
/// subtracted is negated), `None` for no terms.
pub(crate) fn signed_sum(
    terms: impl IntoIterator<Item = (bool, TokenStream)>,
) -> Option<TokenStream> {
    let mut out = TokenStream::new();
    for (i, (negative, term)) in terms.into_iter().enumerate() {
        match (i, negative) {
            (0, false) => {}
            (_, true) => out.extend(quote!(-)),
            (_, false) => out.extend(quote!(+)),
        }
        out.extend(term);
    }
    (!out.is_empty()).then_some(out)
}

/// `let name = value;`, the value moved in.
pub(crate) fn let_statement(name: &impl quote::ToTokens, value: TokenStream) -> TokenStream {
    let mut out = quote! { let #name = };
    out.extend(value);
    out.extend(quote!(;));
    out
}
