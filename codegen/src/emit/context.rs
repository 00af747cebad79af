//! The emission context: one place that knows the generated functions'
//! argument lists, the paths under `::constrained::`, the nalgebra types
//! and values, and how generated locals are named (serde_derive's
//! `Parameters`). Every emitter asks it rather than spelling these out.

use crate::equations::Equations;
use crate::expr::Id;
use crate::names::GENERATED_PREFIX;
use proc_macro2::{Literal, Span, TokenStream};
use quote::{quote, ToTokens};
use std::cell::RefCell;
use std::collections::HashMap;
use syn::Ident;

/// Which arguments a generated function receives.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Inputs {
    /// `(q, t)`: the mass matrix may not depend on velocities.
    Positions,
    /// `(q, qd, t)`.
    States,
}

/// What every emitter of one system shares.
pub(super) struct Context<'a> {
    /// The derived equations being emitted.
    pub eq: &'a Equations,
    /// Number of coordinates `n`.
    pub n: usize,
    /// Number of constraints `k`.
    pub k: usize,
    /// The rank of `A` at consistent states (`k` less the redundancy).
    pub generic_rank: usize,
    /// Straight-line bodies already emitted, by the locals they bind and
    /// their expressions: `gauss` and the Jacobian bind the same `M`, `F`,
    /// `A` and `b`, and a body's CSE schedule and tokens are a tenth of an
    /// expansion. A clone of the tokens shares them.
    pub bodies: RefCell<HashMap<Vec<(Ident, Id)>, TokenStream>>,
}

impl<'a> Context<'a> {
    pub(super) fn new(eq: &'a Equations, generic_rank: usize) -> Self {
        Context {
            eq,
            n: eq.system.dof(),
            k: eq.a.len(),
            generic_rank,
            bodies: RefCell::new(HashMap::new()),
        }
    }

    /// A dimension as an unsuffixed literal (`3`, not `3usize`).
    pub(super) fn dim(size: usize) -> Literal {
        Literal::usize_unsuffixed(size)
    }

    /// `::constrained::item`.
    pub(super) fn path(&self, item: TokenStream) -> TokenStream {
        quote!(::constrained::#item)
    }

    /// `::constrained::__private::item`: generic code that lives once in
    /// the runtime.
    pub(super) fn private(&self, item: TokenStream) -> TokenStream {
        Self::helper(item)
    }

    /// `::constrained::__private::item`, for code that has no context at
    /// hand (expression bodies calling the runtime's scalar helpers).
    pub(super) fn helper(item: TokenStream) -> TokenStream {
        quote!(::constrained::__private::#item)
    }

    /// `SVector<T, len>`.
    pub(super) fn vector(&self, len: usize) -> TokenStream {
        let len = Self::dim(len);
        quote!(::constrained::nalgebra::SVector<T, #len>)
    }

    /// `SMatrix<T, rows, cols>`.
    pub(super) fn matrix(&self, rows: usize, cols: usize) -> TokenStream {
        let (r, c) = (Self::dim(rows), Self::dim(cols));
        quote!(::constrained::nalgebra::SMatrix<T, #r, #c>)
    }

    /// A vector value from its entries.
    pub(super) fn vector_value(
        &self,
        entries: impl IntoIterator<Item = TokenStream>,
    ) -> TokenStream {
        let entries: Vec<TokenStream> = entries.into_iter().collect();
        let len = Self::dim(entries.len());
        quote! {
            ::constrained::nalgebra::SVector::<T, #len>::from_array_storage(
                ::constrained::nalgebra::ArrayStorage([[#(#entries),*]]),
            )
        }
    }

    /// `SMatrix::<T, rows, cols>::zeros()`.
    pub(super) fn matrix_zeros(&self, rows: usize, cols: usize) -> TokenStream {
        let (r, c) = (Self::dim(rows), Self::dim(cols));
        quote!(::constrained::nalgebra::SMatrix::<T, #r, #c>::zeros())
    }

    /// A matrix value from its columns (nalgebra stores columns).
    pub(super) fn matrix_value(&self, rows: usize, columns: Vec<Vec<TokenStream>>) -> TokenStream {
        let (r, c) = (Self::dim(rows), Self::dim(columns.len()));
        let columns = columns.iter().map(|col| quote! { [#(#col),*] });
        quote! {
            ::constrained::nalgebra::SMatrix::<T, #r, #c>::from_array_storage(
                ::constrained::nalgebra::ArrayStorage([#(#columns),*]),
            )
        }
    }

    /// `MultiplierJacobians::<T, n, k, m>::zeros()`: the zeros of `∂λ`'s
    /// struct.
    pub(super) fn multiplier_jacobians_zero(&self) -> TokenStream {
        let (n_l, k_l) = (Self::dim(self.n), Self::dim(self.k));
        let nu_l = Self::dim(self.eq.system.inputs);
        self.path(quote!(linearize::MultiplierJacobians::<T, #n_l, #k_l, #nu_l>::zeros()))
    }

    /// `Jacobians::<T, n, m>::zeros()`, and the number of Jacobian columns
    /// `2n + m` as a literal.
    pub(super) fn jacobians_zero(&self) -> (TokenStream, Literal) {
        let nu = self.eq.system.inputs;
        let (n_l, nu_l) = (Self::dim(self.n), Self::dim(nu));
        (
            self.path(quote!(Jacobians::<T, #n_l, #nu_l>::zeros())),
            Self::dim(2 * self.n + nu),
        )
    }

    /// `Ok(ok)` where every entry of `value` (a `Jacobians`: the local
    /// returned as `ok`, or one written in place, `ok` being `()`) is
    /// finite, else `Err(NonFinite)`.
    pub(super) fn finite_or_error(&self, value: TokenStream, ok: TokenStream) -> TokenStream {
        let non_finite = self.path(quote!(DynamicsError::NonFinite));
        quote! {
            if #value.is_finite() {
                ::core::result::Result::Ok(#ok)
            } else {
                ::core::result::Result::Err(#non_finite)
            }
        }
    }

    /// `Result<ok, ::constrained::error>`.
    pub(super) fn result(&self, ok: TokenStream, error: TokenStream) -> TokenStream {
        let error = self.path(error);
        quote!(::core::result::Result<#ok, #error>)
    }

    /// The parameter list of a generated function (after `&self`).
    pub(super) fn params(&self, inputs: Inputs) -> TokenStream {
        let vector = self.vector(self.n);
        match inputs {
            Inputs::Positions => quote! { q: &#vector, t: T },
            Inputs::States => quote! { q: &#vector, qd: &#vector, t: T },
        }
    }

    /// The matching argument list, to forward a call.
    pub(super) fn args(&self, inputs: Inputs) -> TokenStream {
        match inputs {
            Inputs::Positions => quote! { q, t },
            Inputs::States => quote! { q, qd, t },
        }
    }

    /// The private solver's signature: `gauss`, generic over what its
    /// caller wants back (`constrained::__private::Finish`: `q̈` alone for
    /// the total `acceleration`, `Result<(q̈, Aᵀλ), _>` for the trait).
    pub(super) fn gauss_signature(&self) -> TokenStream {
        let (params, correction) = (self.params(Inputs::States), self.correction_type());
        let (finish, n) = (self.private(quote!(Finish)), Self::dim(self.n));
        quote! {
            fn gauss<__F: #finish<T, #n>>(&self, #params, correction: #correction) -> __F::Output
        }
    }

    /// `gauss`'s exit for an error found before the solve: the caller's
    /// `Finish` decides what it becomes (`Err`, or the least-squares answer).
    pub(super) fn gauss_error(&self, error: TokenStream) -> TokenStream {
        let error = self.path(error);
        quote! {
            return __F::settle(self, q, qd, t, correction, ::core::result::Result::Err(#error));
        }
    }

    /// `self.gauss::<finish>(q, qd, t, correction)`, `finish` one of the
    /// runtime's `Finish` types.
    pub(super) fn call_gauss(&self, finish: &str, correction: TokenStream) -> TokenStream {
        let finish = self.private(Ident::new(finish, Span::call_site()).into_token_stream());
        let args = self.args(Inputs::States);
        quote!(self.gauss::<#finish>(#args, #correction))
    }

    /// The optional correction of `b` taken by `gauss`.
    pub(super) fn correction_type(&self) -> TokenStream {
        let vector = self.vector(self.k);
        quote!(::core::option::Option<&#vector>)
    }

    /// A generated local `__{role}{i}` (role: `t` temporary, `lam`
    /// multiplier, `r` residual, `d` pivot, …).
    pub(super) fn local(role: &str, i: usize) -> Ident {
        Ident::new(&format!("{GENERATED_PREFIX}{role}{i}"), Span::call_site())
    }

    /// A generated local `__{role}{i}_{j}` for a matrix entry.
    pub(super) fn local2(role: &str, i: usize, j: usize) -> Ident {
        Ident::new(
            &format!("{GENERATED_PREFIX}{role}{i}_{j}"),
            Span::call_site(),
        )
    }
}
