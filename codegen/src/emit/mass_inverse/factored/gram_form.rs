//! `gauss`'s solve with constraints once `M` is factored ([`GramForm`]).

use super::{a_column, dot, forces_rhs};
use crate::emit::context::Context;
use crate::emit::ldlt::StructuredLdlt;
use crate::equations::mass_inverse::Factored;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The solver's form of Gauss's principle once `P M Pᵀ = L D Lᵀ` is
/// factored: with `Y = L⁻¹ P Aᵀ` and `z = L⁻¹ P F` (forward
/// substitutions only), `S = Yᵀ D⁻¹ Y`, `r = b − Yᵀ D⁻¹ z`, and after
/// `S λ = r` one back substitution, `q̈ = Pᵀ L⁻ᵀ D⁻¹ (z + Y λ)`. Against
/// forming `W = M⁻¹ Aᵀ` (a back substitution per row of `A`), `S = A W`,
/// `a = M⁻¹ F` and `q̈ = a + W λ`, this skips every back substitution but
/// one, and `Y` is as sparse as the tree makes it (`W` is as dense as the
/// tree is deep). The Jacobian and the projections' step, which need `W`
/// itself, keep that form.
pub(super) struct GramForm {
    /// The forward substitutions, `D⁻¹ Y`, `S`'s entries and `r`.
    pub(super) code: TokenStream,
    /// `r`'s locals.
    pub(super) residuals: Vec<Ident>,
    /// Which positions of `z` are bound (`__ay{p}`).
    z: Vec<bool>,
    /// Which positions of each column of `Y` are bound (`__wy{j}x{p}`).
    y: Vec<Vec<bool>>,
}

/// The [`GramForm`] of `gauss`'s solve: the forward substitutions of `F`
/// and of each row of `A` through `M`'s factor (`mass`), `D⁻¹ Y`, the
/// entries of `S` on `gram`'s pattern, and `r`.
pub(super) fn gram_form(
    ctx: &Context,
    f: &Factored,
    mass: &StructuredLdlt,
    gram: &StructuredLdlt,
) -> GramForm {
    let n = ctx.n;
    let (mut code, z) = mass.forward(&forces_rhs(ctx, f), "ay");
    let mut y = Vec::with_capacity(ctx.k);
    for j in 0..ctx.k {
        let (column, bound) = mass.forward(&a_column(ctx, j), &format!("wy{j}x"));
        code.extend(column);
        // D⁻¹ Y, column by column.
        for p in (0..n).filter(|&p| bound[p]) {
            let (yp, dp, inv) = (
                Context::local(&format!("wy{j}x"), p),
                Context::local(&format!("wd{j}x"), p),
                mass.reciprocal_at(p),
            );
            code.extend(quote! { let #dp = #yp * #inv; });
        }
        y.push(bound);
    }
    code.extend(gram_products(n, gram, &y));
    let residuals: Vec<Ident> = (0..ctx.k).map(|r| Context::local("r", r)).collect();
    for (j, name) in residuals.iter().enumerate() {
        let pairs: Vec<_> = (0..n)
            .filter(|&p| y[j][p] && z[p])
            .map(|p| {
                let (dj, zp) = (
                    Context::local(&format!("wd{j}x"), p),
                    Context::local("ay", p),
                );
                (quote!(#dj), quote!(#zp))
            })
            .collect();
        let b = Context::local("b", j);
        code.extend(if pairs.is_empty() {
            quote! { let #name = #b; }
        } else {
            let yz = dot(pairs);
            quote! { let #name = #b - (#yz); }
        });
    }
    GramForm {
        code,
        residuals,
        z,
        y,
    }
}

/// `S = Yᵀ D⁻¹ Y` on `gram`'s pattern (lower triangle), over the bound
/// positions `y` of each column of `Y`.
fn gram_products(n: usize, gram: &StructuredLdlt, y: &[Vec<bool>]) -> TokenStream {
    let mut code = TokenStream::new();
    for i in 0..y.len() {
        for j in 0..=i {
            let pairs: Vec<_> = (0..n)
                .filter(|&p| y[i][p] && y[j][p])
                .map(|p| {
                    let (yi, dj) = (
                        Context::local(&format!("wy{i}x"), p),
                        Context::local(&format!("wd{j}x"), p),
                    );
                    (quote!(#yi), quote!(#dj))
                })
                .collect();
            if gram.is_nonzero(i, j) {
                let (name, value) = (gram.entry(i, j), dot(pairs));
                code.extend(quote! { let #name = #value; });
            } else {
                debug_assert!(pairs.is_empty(), "S's pattern covers Yᵀ D⁻¹ Y's");
            }
        }
    }
    code
}

impl GramForm {
    /// `q̈ = Pᵀ L⁻ᵀ D⁻¹ (z + Y λ)`: the code binding `__ac{i}` and `q̈`'s
    /// entries (those names, or zero).
    pub(super) fn back_substitution(
        &self,
        ctx: &Context,
        mass: &StructuredLdlt,
        multipliers: &[Ident],
    ) -> (TokenStream, Vec<TokenStream>) {
        let mut code = TokenStream::new();
        let sums: Vec<Option<TokenStream>> = (0..ctx.n)
            .map(|p| {
                let mut terms: Vec<TokenStream> = Vec::new();
                if self.z[p] {
                    let zp = Context::local("ay", p);
                    terms.push(quote!(#zp));
                }
                for (j, lam) in multipliers.iter().enumerate() {
                    if self.y[j][p] {
                        let yp = Context::local(&format!("wy{j}x"), p);
                        terms.push(quote!(#yp * #lam));
                    }
                }
                (!terms.is_empty()).then(|| {
                    let v = Context::local("av", p);
                    code.extend(quote! { let #v = #(#terms)+*; });
                    quote!(#v)
                })
            })
            .collect();
        let out: Vec<Ident> = (0..ctx.n).map(|i| Context::local("ac", i)).collect();
        let (back, bound) = mass.backward(&sums, &out);
        code.extend(back);
        let acceleration = out
            .iter()
            .zip(bound)
            .map(|(x, b)| if b { quote!(#x) } else { quote!(T::zero()) })
            .collect();
        (code, acceleration)
    }
}
