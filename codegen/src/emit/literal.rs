//! Constants as Rust tokens, and the binding strength of emitted
//! expressions (for the parentheses the emitter writes).

use crate::expr::num::Num;
use proc_macro2::{Delimiter, Group, Literal, TokenStream, TokenTree};
use quote::quote;

/// Binding strength of emitted Rust expressions, for parentheses.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Prec {
    Sum,
    Product,
    Unary,
    Atom,
}

/// A constant of type `T`.
///
/// Other than zero and one, a constant is written as a mark that
/// `super::hoist` turns into Rust: its `f64` literal alone in an invisible
/// (`Delimiter::None`) group, a token no other emitted code contains. The
/// call it becomes, `::constrained::__private::lit::<T>(0.5f64)`, is
/// fifteen tokens, and the bodies of a large model read tens of thousands
/// of constants: every stream a constant passes through before the hoist
/// would copy all fifteen.
pub(crate) fn literal(n: Num) -> (TokenStream, Prec) {
    if n.is_zero() {
        return (quote!(T::zero()), Prec::Atom);
    }
    if n.is_one() {
        return (quote!(T::one()), Prec::Atom);
    }
    let value = Literal::f64_suffixed(n.to_f64());
    let mark = Group::new(Delimiter::None, TokenTree::Literal(value).into());
    (TokenTree::Group(mark).into(), Prec::Atom)
}

/// The Rust a constant's mark ([`literal`]) stands for: `value` as a `T`.
pub(super) fn literal_call(value: TokenStream) -> TokenStream {
    quote!(::constrained::__private::lit::<T>(#value))
}
