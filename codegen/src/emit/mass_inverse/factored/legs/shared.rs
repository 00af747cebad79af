//! Legs of one structural pattern sharing one copy of their factor code
//! ([`Shared`]).

use super::{inverse, name, share, Leg};
use crate::emit::context::Context;
use crate::emit::literal::literal;
use crate::equations::legs::Legs;
use crate::expr::num::Num;
use proc_macro2::{Literal, TokenStream};
use quote::quote;
use syn::Ident;

/// The legs' factor code written once, as the nested function
/// `__leg_share`, where every leg has the same structural pattern (which
/// entries of its `J`, `M_ll`, `M_lb`, `E` and right-hand side are
/// nonzero): each leg's `J⁻¹`, `c` and its terms of `S` and `r` are the
/// same arithmetic on other values, and a long solve written out once per
/// leg runs from more code than the instruction cache holds. The function
/// takes the leg's nonzero entries and returns `J⁻¹`, `c`, `S`'s terms
/// (`Eᵀ W + Wᵀ E`, summed) and `r`'s; `None` where `J`'s test fails.
pub(super) struct Shared<'a> {
    legs: &'a Legs,
    /// The saddle-point system's coordinates (its rows follow).
    nr: usize,
    /// Its entries and right-hand side, as [`super::solve`] reads them.
    at: &'a dyn Fn(usize, usize) -> Option<TokenStream>,
    rhs: &'a [Option<TokenStream>],
    /// The function's parameters, in order: the nonzero entries a leg's
    /// share reads, `(i, j)` with `i ≥ j` in the leg's local positions
    /// (its joints `0..3`, the base `3..9`, its foot's rows `9..12`), then
    /// the nonzero right-hand sides.
    entries: Vec<(usize, usize)>,
    sides: Vec<usize>,
    /// The nested function.
    function: TokenStream,
    /// Its outputs after `J⁻¹`: which of `c`'s rows, then the `(m, o)` of
    /// each of `S`'s terms and the `m` of each of `r`'s.
    c: [bool; 3],
    s: Vec<(usize, usize)>,
    r: Vec<usize>,
}

/// A leg's local position `x` ([`Shared::entries`]) in the saddle-point
/// system.
fn global(legs: &Legs, (joints, rows): ([usize; 3], [usize; 3]), nr: usize, x: usize) -> usize {
    match x {
        0..3 => joints[x],
        3..9 => legs.base[x - 3],
        _ => nr + rows[x - 9],
    }
}

impl<'a> Shared<'a> {
    /// `None` where there are fewer than two legs or their patterns differ.
    pub(super) fn new(
        legs: &'a Legs,
        nr: usize,
        at: &'a dyn Fn(usize, usize) -> Option<TokenStream>,
        rhs: &'a [Option<TokenStream>],
    ) -> Option<Shared<'a>> {
        let pattern = |leg: ([usize; 3], [usize; 3])| {
            let g = |x: usize| global(legs, leg, nr, x);
            // What a leg's share reads, in the order it reads them: `J`,
            // `M_ll`, `M_lb`, `E`, then the rows' and the joints' sides.
            let j = (9..12).flat_map(|r| (0..3).map(move |k| (r, k)));
            let mll = (0..3).flat_map(|i| (0..=i).map(move |k| (i, k)));
            let mlb = (0..3).flat_map(|i| (3..9).map(move |m| (m, i)));
            let e = (9..12).flat_map(|r| (3..9).map(move |m| (r, m)));
            let entries: Vec<(usize, usize)> = j
                .chain(mll)
                .chain(mlb)
                .chain(e)
                .filter(|&(i, k)| at(g(i), g(k)).is_some())
                .collect();
            let sides: Vec<usize> = (9..12)
                .chain(0..3)
                .filter(|&x| rhs[g(x)].is_some())
                .collect();
            (entries, sides)
        };
        let first = pattern(*legs.legs.first()?);
        if legs.legs.len() < 2 || legs.legs[1..].iter().any(|&leg| pattern(leg) != first) {
            return None;
        }
        let (entries, sides) = first;
        let mut shared = Shared {
            legs,
            nr,
            at,
            rhs,
            entries,
            sides,
            function: TokenStream::new(),
            c: [false; 3],
            s: Vec::new(),
            r: Vec::new(),
        };
        shared.write_function();
        Some(shared)
    }

    /// The parameter that holds local entry `(i, j)` or right-hand side
    /// `x` (`j = None`), where nonzero.
    fn parameter(&self, i: usize, j: Option<usize>) -> Option<TokenStream> {
        let name = match j {
            Some(j) => {
                let (i, j) = (i.max(j), i.min(j));
                self.entries.contains(&(i, j)).then(|| name("lp", i, j))?
            }
            None => self.sides.contains(&i).then(|| Context::local("lpr", i))?,
        };
        Some(quote!(#name))
    }

    /// The nested function: [`super::share`]'s arithmetic on the
    /// parameters, in leg 0's locals, `S`'s two terms at each entry summed.
    fn write_function(&mut self) {
        let at = |i: usize, j: usize| self.parameter(i, Some(j));
        let rhs: Vec<Option<TokenStream>> = (0..12).map(|x| self.parameter(x, None)).collect();
        let leg = Leg {
            t: 0,
            inverse: [0, 1, 2].map(|i| [0, 1, 2].map(|k| name("lja", 0, 3 * i + k))),
            at: &at,
            joints: [0, 1, 2],
            rows: [0, 1, 2],
            base: [3, 4, 5, 6, 7, 8],
            nr: 9,
        };
        let j = |i: usize, k: usize| at(9 + i, k);
        // The enclosing body's constants, written as it writes them: the
        // function binds its own (`crate::emit::hoist`).
        let (tolerance, _) = literal(Num::Rational(1, 1000));
        let (half, _) = literal(Num::Rational(1, 2));
        let mut body = inverse(
            0,
            &j,
            &quote!(return ::core::option::Option::None;),
            &tolerance,
        );
        let mut s_terms = vec![vec![Vec::new(); 6]; 6];
        let mut r_terms = vec![Vec::new(); 6];
        let terms = (&mut s_terms[..], &mut r_terms[..]);
        let c = share(&leg, &rhs, &mut body, terms, Some(&half));
        let mut outputs: Vec<TokenStream> =
            leg.inverse.iter().flatten().map(|a| quote!(#a)).collect();
        outputs.extend(c.iter().flatten().map(|c| quote!(#c)));
        for (m, row) in s_terms.iter().enumerate() {
            for (o, terms) in row.iter().enumerate().take(m + 1) {
                if terms.is_empty() {
                    continue;
                }
                let sum = name("ljss", m, o);
                body.extend(quote! { let #sum = #(#terms)+*; });
                outputs.push(quote!(#sum));
                self.s.push((m, o));
            }
        }
        for (m, terms) in r_terms.iter().enumerate() {
            outputs.extend(terms.iter().cloned());
            self.r.extend(terms.iter().map(|_| m));
        }
        self.c = c.map(|c| c.is_some());
        let inputs = self.entries.iter().map(|&(i, j)| name("lp", i, j));
        let inputs = inputs.chain(self.sides.iter().map(|&x| Context::local("lpr", x)));
        let inputs: Vec<Ident> = inputs.collect();
        let (n_in, n_out) = (
            Literal::usize_unsuffixed(inputs.len()),
            Literal::usize_unsuffixed(outputs.len()),
        );
        self.function = quote! {
            #[inline(never)]
            fn __leg_share<T: ::constrained::nalgebra::RealField + Copy>(
                __inputs: &[T; #n_in],
            ) -> ::core::option::Option<[T; #n_out]> {
                let [#(#inputs),*] = *__inputs;
                #body
                ::core::option::Option::Some([#(#outputs),*])
            }
        };
    }

    /// The nested function, to write before the first [`Shared::call`].
    pub(super) fn function(&self) -> TokenStream {
        self.function.clone()
    }

    /// The call for `leg`: its `J⁻¹` and `c` bound as [`super::share`] binds them
    /// (`c` returned), its terms pushed into `S`'s and `r`'s, `dense` where
    /// its `J` fails the test.
    pub(super) fn call(
        &self,
        leg: &Leg,
        dense: &TokenStream,
        code: &mut TokenStream,
        (s_terms, r_terms): (&mut [Vec<Vec<TokenStream>>], &mut [Vec<TokenStream>]),
    ) -> [Option<Ident>; 3] {
        let g = |x: usize| global(self.legs, (leg.joints, leg.rows), self.nr, x);
        let entries = self
            .entries
            .iter()
            .filter_map(|&(i, j)| (self.at)(g(i), g(j)));
        let sides = self.sides.iter().filter_map(|&x| self.rhs[g(x)].clone());
        let args: Vec<TokenStream> = entries.chain(sides).collect();
        let t = leg.t;
        let c = [0, 1, 2].map(|i| self.c[i].then(|| name("ljc", t, i)));
        let mut names: Vec<Ident> = leg.inverse.iter().flatten().cloned().collect();
        names.extend(c.iter().flatten().cloned());
        for (x, &(m, o)) in self.s.iter().enumerate() {
            let term = name("ljsh", t, x);
            s_terms[m][o].push(quote!(#term));
            names.push(term);
        }
        for (x, &m) in self.r.iter().enumerate() {
            let term = name("ljrh", t, x);
            r_terms[m].push(quote!(#term));
            names.push(term);
        }
        let out = Context::local("ljo", t);
        code.extend(quote! {
            let ::core::option::Option::Some(#out) = __leg_share::<T>(&[#(#args),*]) else {
                #dense
            };
            let [#(#names),*] = #out;
        });
        c
    }
}
