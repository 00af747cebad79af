//! Constants as Rust tokens, and the binding strength of emitted
//! expressions (for the parentheses the emitter writes).

use crate::expr::num::Num;
use proc_macro2::{Literal, TokenStream};
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
pub(crate) fn literal(n: Num) -> (TokenStream, Prec) {
    if n.is_zero() {
        return (quote!(T::zero()), Prec::Atom);
    }
    if n.is_one() {
        return (quote!(T::one()), Prec::Atom);
    }
    let value = Literal::f64_suffixed(n.to_f64());
    (
        quote!(::constrained::__private::lit::<T>(#value)),
        Prec::Atom,
    )
}
