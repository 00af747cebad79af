//! `X y = r` by `P X Pᵀ = L D Lᵀ` in a compile-time elimination order over
//! the compile-time pattern (fill included), emitted as two steps: the
//! factorization (once), then a solve per right-hand side (as often as
//! there are right-hand sides), each with its own names. Two matrices are
//! factored this way: `S = A M⁻¹ Aᵀ` and a configuration-dependent `M`.
//!
//! Only structural nonzeros are touched, so a chain's tridiagonal `S` costs
//! O(k), and a solve for a sparse right-hand side touches only the entries
//! it can reach. `S`'s pivots are rank-revealing: one whose
//! `sin²θ = dⱼ / Sⱼⱼ` is below `rank_tolerance` is dropped (`D⁺`), which
//! removes its constraint; for k = 1 this is the scalar closed form
//! `λ = r / S` with `λ = 0` where `S = 0`. A drop the model's redundancy
//! does not explain is flagged ([`StructuredLdlt::suspect`]) and verified at
//! run time (`constrained::rank`). `M`'s pivots must be positive, as in a
//! Cholesky factorization: otherwise `M` is not positive definite there,
//! and the function returns that error.

mod inverse;
mod minimum_norm;
mod signed;
mod suspect;

pub(super) use minimum_norm::Rows;

use super::context::Context;
use crate::numeric::sparsity::Structure;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The roles of the generated locals of one factorization.
struct Roles {
    /// The matrix's entries (bound by the caller).
    entry: &'static str,
    /// Pivots `dⱼ`.
    pivot: &'static str,
    /// Their reciprocals.
    inverse: &'static str,
    /// Schur-updated (unscaled) entries.
    update: &'static str,
    /// The unit lower factor.
    lower: &'static str,
}

/// What a pivot may be.
enum Pivots {
    /// Rank-revealing: a small pivot is dropped (`S`).
    Dropped,
    /// Positive, or the given statement runs (a `return` of the function's
    /// error: `M`).
    Positive(TokenStream),
    /// Positive and finite, else the first statement runs where the pivot
    /// is finite and the second where it is not: `M` whose entries are not
    /// checked before (a non-finite entry makes a pivot non-finite, see
    /// [`StructuredLdlt::mass_checked`]).
    PositiveFinite(TokenStream, TokenStream),
    /// The saddle-point matrix (`crate::equations::saddle_point`): rows
    /// below `coordinates` positive, the multipliers' negative and `−dⱼ`
    /// above `10⁻³` times the part their coordinates gave;
    /// otherwise the statement runs (the runtime's dense solve answers).
    Signed {
        coordinates: usize,
        bail: TokenStream,
    },
}

/// How often the function solves with the factorization.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Solves {
    /// Once: the last pivot, which only the solve reads, divides there
    /// instead of forming its reciprocal (one operation fewer).
    Once,
    /// More than once: every pivot's reciprocal is formed once and shared.
    Many,
}

/// The factorization of one symmetric matrix, whose entries are the locals
/// named by [`StructuredLdlt::entry`] (i ≥ j, structural nonzeros only).
pub(super) struct StructuredLdlt<'a> {
    structure: &'a Structure,
    roles: Roles,
    pivots: Pivots,
    solves: Solves,
}

impl<'a> StructuredLdlt<'a> {
    /// `S = A M⁻¹ Aᵀ`: entries `__s{i}_{j}`, rank-revealing pivots.
    pub(super) fn gram(structure: &'a Structure) -> Self {
        StructuredLdlt {
            structure,
            roles: Roles {
                entry: "s",
                pivot: "d",
                inverse: "inv",
                update: "u",
                lower: "l",
            },
            pivots: Pivots::Dropped,
            solves: Solves::Many,
        }
    }

    /// `M(q)`: entries `__m{i}_{j}`, pivots that must be positive, else
    /// `bail` runs (a `return` statement); `solves`: how often the function
    /// solves with it.
    pub(super) fn mass(structure: &'a Structure, bail: TokenStream, solves: Solves) -> Self {
        StructuredLdlt {
            structure,
            roles: Roles {
                entry: "m",
                pivot: "md",
                inverse: "mi",
                update: "mu",
                lower: "ml",
            },
            pivots: Pivots::Positive(bail),
            solves,
        }
    }

    /// `M(q)` whose entries were not checked finite: the pivots are. An
    /// entry reaches its column's pivot (on the diagonal) or, off it, its
    /// Schur-updated `u`, whose square enters a later pivot: with every
    /// pivot finite and positive, every `u` and `l` is finite, and so is
    /// every entry. A pivot that is finite and not positive runs
    /// `not_positive`; one that is not finite, `non_finite`.
    pub(super) fn mass_checked(
        structure: &'a Structure,
        (not_positive, non_finite): (TokenStream, TokenStream),
        solves: Solves,
    ) -> Self {
        StructuredLdlt {
            pivots: Pivots::PositiveFinite(not_positive, non_finite),
            ..Self::mass(structure, TokenStream::new(), solves)
        }
    }

    /// A floating base's 6 × 6 inertia with its feet's legs eliminated
    /// (`super::mass_inverse::factored::legs`): entries `__bs{i}_{j}`,
    /// pivots that must be positive, else `bail` runs; solved once.
    pub(super) fn reduced(structure: &'a Structure, bail: TokenStream) -> Self {
        StructuredLdlt {
            structure,
            roles: Roles {
                entry: "bs",
                pivot: "bsd",
                inverse: "bsi",
                update: "bsx",
                lower: "bsl",
            },
            pivots: Pivots::Positive(bail),
            solves: Solves::Once,
        }
    }

    /// The saddle-point matrix `[M Aᵀ; A 0]` (rows `0..n` the coordinates):
    /// entries `__k{i}_{j}`, signed pivots, `bail` where one fails.
    pub(super) fn saddle(structure: &'a Structure, n: usize, bail: TokenStream) -> Self {
        StructuredLdlt {
            structure,
            roles: Roles {
                entry: "k",
                pivot: "kd",
                inverse: "ki",
                update: "ku",
                lower: "kl",
            },
            pivots: Pivots::Signed {
                coordinates: n,
                bail,
            },
            solves: Solves::Many,
        }
    }

    /// Whether pivot `j`'s reciprocal is formed: not the last one's where
    /// the function solves once (nothing in the factorization reads it).
    fn reciprocal(&self, j: usize) -> bool {
        !(self.solves == Solves::Once && j + 1 == self.k())
    }

    /// The local holding entry (i, j) of the matrix.
    pub(super) fn entry(&self, i: usize, j: usize) -> Ident {
        Context::local2(self.roles.entry, i.max(j), i.min(j))
    }

    fn k(&self) -> usize {
        self.structure.len()
    }

    /// The entry at positions `p`, `q` of the elimination order.
    fn at(&self, p: usize, q: usize) -> TokenStream {
        let (i, j) = (self.structure.order[p], self.structure.order[q]);
        if self.structure.nonzero[i][j] {
            let name = self.entry(i, j);
            quote!(#name)
        } else {
            quote!(T::zero())
        }
    }

    /// Whether this is `S`'s scalar case, solved in closed form.
    fn scalar_gram(&self) -> bool {
        self.k() == 1 && matches!(self.pivots, Pivots::Dropped)
    }

    /// The factor step: pivots `dⱼ`, their reciprocals, the Schur-updated
    /// entries `uᵢⱼ` and the unit lower factor `lᵢⱼ`, all by position in
    /// the elimination order.
    ///
    /// With u the Schur-updated (unscaled) entries and l = u·inv:
    ///   dⱼ = Xⱼⱼ − Σ_c (u_jc·u_jc)·inv_c,  u_ij = X_ij − Σ_c u_ic·l_jc,  l_ij = u_ij·inv_j.
    /// (u·u)·inv equals l·l·d (inv·d = 1 for a kept pivot, both 0 for a
    /// dropped one) but leaves one multiplication, not three, between a
    /// pivot's reciprocal and the next division: the recurrence is the
    /// critical path of a chain, so this is what its cost per link is made of.
    pub(super) fn factor(&self) -> TokenStream {
        let k = self.k();
        if k == 0 || self.scalar_gram() {
            return TokenStream::new(); // k = 1 divides by S itself in `solve`
        }
        let mut out = match self.pivots {
            Pivots::Dropped => {
                let rank_tolerance = quote!(::constrained::inverse::rank_tolerance::<T>());
                quote! { let __tol: T = #rank_tolerance; }
            }
            // Growth of at most 10³ in the pivots without pivoting: about
            // 10⁻¹³ relative where the dense solve's is 10⁻¹⁶. The same
            // `sin²θ` test as a redundant set's kept pivots
            // (`constrained::rank::conditioning_tolerance`).
            Pivots::Signed { .. } => {
                let tolerance = quote!(::constrained::__private::conditioning_tolerance::<T>());
                quote! { let __tol: T = #tolerance; }
            }
            Pivots::Positive(_) | Pivots::PositiveFinite(..) => TokenStream::new(),
        };
        for j in 0..k {
            out.extend(match &self.pivots {
                Pivots::Signed { coordinates, bail } => self.signed_pivot(j, *coordinates, bail),
                _ => self.pivot(j),
            });
            out.extend(self.column(j));
        }
        out
    }

    /// Pivot `j` and its reciprocal, for `S` (dropped where small) and `M`
    /// (positive).
    fn pivot(&self, j: usize) -> TokenStream {
        let (l, r) = (&self.structure.fill, &self.roles);
        let (dj, inv, xjj) = (
            Context::local(r.pivot, j),
            Context::local(r.inverse, j),
            self.at(j, j),
        );
        let updated = (0..j).any(|c| l[j][c]);
        let updates = (0..j).filter(|&c| l[j][c]).map(|c| {
            let (ujc, invc) = (
                Context::local2(r.update, j, c),
                Context::local(r.inverse, c),
            );
            quote!(- (#ujc * #ujc) * #invc)
        });
        let mut out = quote! { let #dj = #xjj #(#updates)*; };
        out.extend(match &self.pivots {
            // A pivot nothing updated is its diagonal entry, and
            // `d > tol·d` is `d > 0`: NaN gives 0 either way, and ∞,
            // which `d > tol·d` dropped, gives `1/∞ = 0` here, the same
            // reciprocal and the same "dropped" (`inv == 0`).
            Pivots::Dropped if !updated => quote! {
                let #inv = if #dj > T::zero() { T::one() / #dj } else { T::zero() };
            },
            Pivots::Dropped => quote! {
                let #inv = if #dj > __tol * #xjj { T::one() / #dj } else { T::zero() };
            },
            // `!(d > 0)` also catches NaN.
            Pivots::Positive(bail) | Pivots::Signed { bail, .. } => {
                let reciprocal = self
                    .reciprocal(j)
                    .then(|| quote! { let #inv = T::one() / #dj; });
                quote! {
                    if !(#dj > T::zero()) {
                        #bail
                    }
                    #reciprocal
                }
            }
            Pivots::PositiveFinite(not_positive, non_finite) => {
                let reciprocal = self
                    .reciprocal(j)
                    .then(|| quote! { let #inv = T::one() / #dj; });
                quote! {
                    if !(#dj > T::zero() && #dj.is_finite()) {
                        if #dj.is_finite() {
                            #not_positive
                        }
                        #non_finite
                    }
                    #reciprocal
                }
            }
        });
        out
    }

    /// Column `j` of the factor below its pivot: the Schur-updated entries
    /// `uᵢⱼ` and `lᵢⱼ = uᵢⱼ·invⱼ`.
    fn column(&self, j: usize) -> TokenStream {
        let (l, r) = (&self.structure.fill, &self.roles);
        let inv = Context::local(r.inverse, j);
        let mut out = TokenStream::new();
        for i in j + 1..self.k() {
            if !l[i][j] {
                continue;
            }
            let (lij, uij, xij) = (
                Context::local2(r.lower, i, j),
                Context::local2(r.update, i, j),
                self.at(i, j),
            );
            let products: Vec<TokenStream> = (0..j)
                .filter(|&c| l[i][c] && l[j][c])
                .map(|c| {
                    let (uic, ljc) = (
                        Context::local2(r.update, i, c),
                        Context::local2(r.lower, j, c),
                    );
                    quote!(#uic * #ljc)
                })
                .collect();
            // The saddle-point matrix's updates of the base run over every
            // leg: a balanced tree shortens their dependency chain at the
            // same operation count, which pays in the factorization; the
            // solves keep the plain order, where the tree does not pay.
            let value = if matches!(self.pivots, Pivots::Signed { .. }) && products.len() > 2 {
                let sum = balanced(products);
                quote!(#xij - #sum)
            } else {
                quote!(#xij #(- #products)*)
            };
            out.extend(quote! {
                let #uij = #value;
                let #lij = #uij * #inv;
            });
        }
        out
    }

    /// Whether the factorization kept row `row` (its pivot was not
    /// dropped), as a `bool` expression.
    pub(super) fn kept(&self, row: usize) -> TokenStream {
        if self.scalar_gram() {
            let s = self.at(0, 0);
            return quote!(#s > T::zero());
        }
        let p = self
            .structure
            .order
            .iter()
            .position(|&r| r == row)
            .expect("every row has a position");
        let inv = Context::local(self.roles.inverse, p);
        quote!(#inv != T::zero())
    }

    /// The solve step for the right-hand side `rhs` (one local per row, in
    /// natural order): forward substitution into `__{y}{p}`, then back
    /// substitution into `out` (one local per row). `y` names the
    /// intermediate locals, so that several solves can follow one
    /// factorization.
    pub(super) fn solve(&self, rhs: &[Ident], y: &str, out: &[Ident]) -> TokenStream {
        let rhs: Vec<Option<TokenStream>> = rhs.iter().map(|r| Some(quote!(#r))).collect();
        self.solve_sparse(&rhs, y, out).0
    }

    /// `S`'s scalar case (`k = 1`) as the solver's fast path writes it:
    /// `λ = r / S` bare, for use only where [`suspect`](Self::suspect) is
    /// false (then `S` lies in (safe minimum, largest], so the division is
    /// safe). `None` where `S` is not a scalar.
    pub(super) fn scalar_division(&self, r: &Ident, lam: &Ident) -> Option<TokenStream> {
        self.scalar_gram().then(|| {
            let s = self.at(0, 0);
            quote! { let #lam = #r / #s; }
        })
    }

    /// The solve step for a right-hand side with structural zeros (`None`):
    /// only the entries it can reach are computed. Returns the code and
    /// which of `out` it binds; the others are zero.
    pub(super) fn solve_sparse(
        &self,
        rhs: &[Option<TokenStream>],
        y: &str,
        out: &[Ident],
    ) -> (TokenStream, Vec<bool>) {
        let k = self.k();
        if k == 0 {
            return (TokenStream::new(), Vec::new());
        }
        if self.scalar_gram() {
            // `S` may be structurally zero (a row of `A` that simplifies to
            // 0): then the literal zero, and λ = 0.
            let Some(r) = &rhs[0] else {
                return (TokenStream::new(), vec![false]);
            };
            let (lam, s) = (&out[0], self.at(0, 0));
            let code = quote! {
                let #lam = if #s > T::zero() { #r / #s } else { T::zero() };
            };
            return (code, vec![true]);
        }
        let (mut code, forward) = self.forward(rhs, y);
        let values: Vec<Option<TokenStream>> = (0..k)
            .map(|p| {
                forward[p].then(|| {
                    let yp = Context::local(y, p);
                    quote!(#yp)
                })
            })
            .collect();
        let (back, bound) = self.backward(&values, out);
        code.extend(back);
        (code, bound)
    }

    /// Forward substitution `y = L⁻¹ P rhs` for a right-hand side with
    /// structural zeros (`None`, `rhs` in natural order) into the locals
    /// `__{y}{p}`, by position `p` in the elimination order; returns the
    /// code and which positions it binds (the others are zero).
    pub(super) fn forward(&self, rhs: &[Option<TokenStream>], y: &str) -> (TokenStream, Vec<bool>) {
        let k = self.k();
        let (l, o) = (&self.structure.fill, &self.structure.order);
        let mut code = TokenStream::new();
        let mut forward = vec![false; k];
        for i in 0..k {
            let yi = Context::local(y, i);
            let updates: Vec<TokenStream> = (0..i)
                .filter(|&c| l[i][c] && forward[c])
                .map(|c| {
                    let (lic, yc) = (
                        Context::local2(self.roles.lower, i, c),
                        Context::local(y, c),
                    );
                    quote!(#lic * #yc)
                })
                .collect();
            let value = match (&rhs[o[i]], updates.is_empty()) {
                (None, true) => continue,
                (Some(r), _) => quote!(#r #(- #updates)*),
                (None, false) => {
                    let (first, rest) = updates.split_first().expect("non-empty");
                    quote!(-(#first) #(- #rest)*)
                }
            };
            code.extend(quote! { let #yi = #value; });
            forward[i] = true;
        }
        (code, forward)
    }

    /// Back substitution `x = Pᵀ L⁻ᵀ D⁻¹ y` into `out` (one local per row,
    /// natural order), from `y` given by position in the elimination order
    /// (`None`: structurally zero); returns the code and which of `out` it
    /// binds (the others are zero).
    pub(super) fn backward(
        &self,
        y: &[Option<TokenStream>],
        out: &[Ident],
    ) -> (TokenStream, Vec<bool>) {
        let k = self.k();
        let (l, o) = (&self.structure.fill, &self.structure.order);
        let mut code = TokenStream::new();
        let mut back = vec![false; k];
        for i in (0..k).rev() {
            let (x, inv) = (&out[o[i]], Context::local(self.roles.inverse, i));
            let updates: Vec<TokenStream> = (i + 1..k)
                .filter(|&c| l[c][i] && back[c])
                .map(|c| {
                    let (lci, xc) = (Context::local2(self.roles.lower, c, i), &out[o[c]]);
                    quote!(#lci * #xc)
                })
                .collect();
            let value = match (&y[i], updates.is_empty()) {
                (None, true) => continue,
                (Some(yi), _) => {
                    let scaled = if self.reciprocal(i) {
                        quote!(#yi * #inv)
                    } else {
                        let di = Context::local(self.roles.pivot, i);
                        quote!(#yi / #di)
                    };
                    quote!(#scaled #(- #updates)*)
                }
                (None, false) => {
                    let (first, rest) = updates.split_first().expect("non-empty");
                    quote!(-(#first) #(- #rest)*)
                }
            };
            code.extend(quote! { let #x = #value; });
            back[i] = true;
        }
        let mut bound = vec![false; k];
        for (p, &row) in o.iter().enumerate() {
            bound[row] = back[p];
        }
        (code, bound)
    }

    /// The local holding pivot `p`'s reciprocal (position `p` in the
    /// elimination order).
    pub(super) fn reciprocal_at(&self, p: usize) -> Ident {
        Context::local(self.roles.inverse, p)
    }

    /// The block of each row of the matrix (natural order), rows coupled
    /// through its nonzeros sharing one (`Structure::blocks`).
    pub(super) fn blocks(&self) -> Vec<usize> {
        self.structure.blocks()
    }

    /// Whether entry (i, j) of the matrix is a structural nonzero.
    pub(super) fn is_nonzero(&self, i: usize, j: usize) -> bool {
        self.structure.nonzero[i.max(j)][i.min(j)]
    }
}

/// `Σ terms` as a balanced tree, `((a + b) + (c + d))`: the same additions
/// as `a + b + c + d`, in log₂ n dependent steps instead of n − 1.
fn balanced(mut terms: Vec<TokenStream>) -> TokenStream {
    while terms.len() > 1 {
        let mut next = Vec::with_capacity(terms.len().div_ceil(2));
        let mut pairs = terms.into_iter();
        while let Some(a) = pairs.next() {
            next.push(match pairs.next() {
                Some(b) => quote!((#a + #b)),
                None => a,
            });
        }
        terms = next;
    }
    terms.pop().unwrap_or_else(|| quote!(T::zero()))
}
