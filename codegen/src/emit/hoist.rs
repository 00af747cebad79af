//! Each constant a generated function reads more than once, bound once
//! at its top.
//!
//! The emitter writes a constant where it is used,
//! `::constrained::__private::lit::<T>(0.5f64)` (`super::literal`), and a
//! large model's methods read tens of thousands of them: 31,538 in the
//! standing G1's expansion, 3,385 distinct within their function. Each is
//! a call of a generic function that the compiler type-checks,
//! borrow-checks and lowers on its own, a basic block of every later pass;
//! bound once, they leave the passes a tenth of the calls: a binary that
//! calls the standing G1's `acceleration` builds in 6 % less CPU and 7 %
//! less peak memory than with every constant in place (paired builds).
//! The values are the same, and the machine code too: `lit` converts a
//! literal, which the optimizer folds into the instructions that read it
//! (the methods measured compile to the same number of bytes). All of a
//! function's bindings are one statement, `let [__lit0, __lit1, ..]: [T;
//! K] = [..];`, so that they open one lexical scope however many they are
//! (`super::chunks`). A function defined inside a body (`__leg_share`)
//! is an item, out of reach of the body's bindings: it binds its own.

use proc_macro2::{Delimiter, Group, Ident, Span, TokenStream, TokenTree};
use quote::{format_ident, quote};
use std::collections::HashMap;

/// `items` with every function body's constants bound at its top
/// ([`hoisted`]); the other tokens as they are.
pub(super) fn literals(items: TokenStream) -> TokenStream {
    let tokens: Vec<TokenTree> = items.into_iter().collect();
    let mut out: Vec<TokenTree> = Vec::with_capacity(tokens.len());
    let mut i = 0;
    while i < tokens.len() {
        if let Some(end) = function_at(&tokens, i) {
            function(&tokens[i..end], &mut out);
            i = end;
            continue;
        }
        out.push(match &tokens[i] {
            TokenTree::Group(g) => TokenTree::Group(regroup(g, literals(g.stream()))),
            t => t.clone(),
        });
        i += 1;
    }
    out.into_iter().collect()
}

/// A function body with each constant it reads more than once replaced
/// by `__lit{k}`, in the order they first appear, bound by one statement
/// before the rest. A constant read once stays where it is: binding it
/// would spare no call, and the number reads better in place.
fn hoisted(body: &Group) -> Group {
    let mut reads: HashMap<String, usize> = HashMap::new();
    count(body.stream(), &mut reads);
    let mut names: HashMap<String, Ident> = HashMap::new();
    let mut bound: Vec<(Ident, TokenStream)> = Vec::new();
    let stream = replaced(body.stream(), &reads, &mut names, &mut bound);
    if bound.is_empty() {
        return body.clone();
    }
    let (idents, values): (Vec<Ident>, Vec<TokenStream>) = bound.into_iter().unzip();
    let length = proc_macro2::Literal::usize_unsuffixed(idents.len());
    let mut out = quote! {
        let [#(#idents),*]: [T; #length] = [#(#values),*];
    };
    out.extend(stream);
    regroup(body, out)
}

/// How many times `stream` reads each constant, by its argument's text.
fn count(stream: TokenStream, reads: &mut HashMap<String, usize>) {
    let tokens: Vec<TokenTree> = stream.into_iter().collect();
    let mut i = 0;
    while i < tokens.len() {
        if let Some(end) = function_at(&tokens, i) {
            i = end;
            continue;
        }
        if let Some(argument) = constant_at(&tokens, i) {
            *reads.entry(argument.to_string()).or_insert(0) += 1;
            i += LIT_PATH.len() + 1;
            continue;
        }
        if let TokenTree::Group(g) = &tokens[i] {
            count(g.stream(), reads);
        }
        i += 1;
    }
}

/// `stream` with each `::constrained::__private::lit::<T>(c)` that
/// `reads` counts more than once replaced by the name of `c`, a new one
/// (with the call it stands for) appended to `bound` on first sight.
fn replaced(
    stream: TokenStream,
    reads: &HashMap<String, usize>,
    names: &mut HashMap<String, Ident>,
    bound: &mut Vec<(Ident, TokenStream)>,
) -> TokenStream {
    let tokens: Vec<TokenTree> = stream.into_iter().collect();
    let mut out: Vec<TokenTree> = Vec::with_capacity(tokens.len());
    let mut i = 0;
    while i < tokens.len() {
        // A function defined in the body (`__leg_share`) is an item, which
        // cannot read the body's bindings: it binds its own constants (and
        // `count` leaves its reads out of the body's).
        if let Some(end) = function_at(&tokens, i) {
            function(&tokens[i..end], &mut out);
            i = end;
            continue;
        }
        if let Some(argument) = constant_at(&tokens, i) {
            let end = i + LIT_PATH.len() + 1;
            let key = argument.to_string();
            if reads.get(&key).is_some_and(|&n| n > 1) {
                let name = names.entry(key).or_insert_with(|| {
                    let name = format_ident!("__lit{}", bound.len(), span = Span::call_site());
                    bound.push((name.clone(), tokens[i..end].iter().cloned().collect()));
                    name
                });
                out.push(TokenTree::Ident(name.clone()));
            } else {
                out.extend(tokens[i..end].iter().cloned());
            }
            i = end;
            continue;
        }
        out.push(match &tokens[i] {
            TokenTree::Group(g) => {
                TokenTree::Group(regroup(g, replaced(g.stream(), reads, names, bound)))
            }
            t => t.clone(),
        });
        i += 1;
    }
    out.into_iter().collect()
}

/// The tokens of `::constrained::__private::lit::<T>`, as `literal` writes
/// them: an identifier, or a punctuation character.
const LIT_PATH: [&str; 14] = [
    ":",
    ":",
    "constrained",
    ":",
    ":",
    "__private",
    ":",
    ":",
    "lit",
    ":",
    ":",
    "<",
    "T",
    ">",
];

/// The parenthesized argument where `tokens[i..]` is `lit::<T>(..)` by its
/// full path.
fn constant_at(tokens: &[TokenTree], i: usize) -> Option<&Group> {
    let path = tokens.get(i..i + LIT_PATH.len())?;
    let matches = path.iter().zip(LIT_PATH).all(|(t, want)| match t {
        TokenTree::Ident(id) => id == want,
        TokenTree::Punct(p) => want.len() == 1 && want.starts_with(p.as_char()),
        _ => false,
    });
    match tokens.get(i + LIT_PATH.len()) {
        Some(TokenTree::Group(g)) if matches && g.delimiter() == Delimiter::Parenthesis => Some(g),
        _ => None,
    }
}

/// Where `tokens[i..]` is a function item (`fn name … { … }`, or a
/// declaration, which ends at its `;`), the position just past it;
/// `None` elsewhere.
fn function_at(tokens: &[TokenTree], i: usize) -> Option<usize> {
    let is_fn = matches!(&tokens[i], TokenTree::Ident(id) if id == "fn")
        && matches!(tokens.get(i + 1), Some(TokenTree::Ident(_)));
    if !is_fn {
        return None;
    }
    let last = tokens[i..].iter().position(|t| match t {
        TokenTree::Group(g) => g.delimiter() == Delimiter::Brace,
        TokenTree::Punct(p) => p.as_char() == ';',
        _ => false,
    })?;
    Some(i + last + 1)
}

/// The function item `tokens` ([`function_at`]) into `out`, its body's
/// constants bound at its top ([`hoisted`]).
fn function(tokens: &[TokenTree], out: &mut Vec<TokenTree>) {
    let Some((last, signature)) = tokens.split_last() else {
        return;
    };
    out.extend(signature.iter().cloned());
    out.push(match last {
        TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => TokenTree::Group(hoisted(g)),
        t => t.clone(),
    });
}

/// A group with the delimiter and span of `like` around `stream`.
fn regroup(like: &Group, stream: TokenStream) -> Group {
    let mut g = Group::new(like.delimiter(), stream);
    g.set_span(like.span());
    g
}

#[cfg(test)]
mod tests {
    use super::literals;
    use quote::quote;

    /// A function defined in a body binds the constants it reads twice
    /// itself, and the body's bindings count only the body's own reads: a
    /// constant read once in each stays in place in both, where counted
    /// together it was bound in the body and read in the function, which
    /// cannot see it.
    #[test]
    fn a_function_in_a_body_binds_its_own_constants() {
        let lit = |x: f64| quote!(::constrained::__private::lit::<T>(#x));
        let (a, b, c) = (lit(1.5), lit(2.5), lit(3.5));
        let items = quote! {
            fn outer<T>() -> T {
                let x = #a + #a + #c;
                fn inner<T>() -> T { #b * #b + #c }
                x + #b
            }
        };
        let out = literals(items).to_string();
        let (outer, inner) = out.split_once("fn inner").expect("the nested function");
        let (inner, after) = inner.split_once('}').expect("its body");
        // The body binds 1.5 (read twice there) and not 2.5 or 3.5 (once each).
        assert!(
            outer.contains(
                "let [__lit0] : [T ; 1] = [:: constrained :: __private :: lit :: < T > (1.5f64)]"
            ),
            "{outer}"
        );
        // The function binds 2.5 and reads 3.5 in place.
        assert!(
            inner.contains(
                "let [__lit0] : [T ; 1] = [:: constrained :: __private :: lit :: < T > (2.5f64)]"
            ),
            "{inner}"
        );
        assert!(
            inner
                .contains("__lit0 * __lit0 + :: constrained :: __private :: lit :: < T > (3.5f64)"),
            "{inner}"
        );
        assert!(
            after.contains("x + :: constrained :: __private :: lit :: < T > (2.5f64)"),
            "{after}"
        );
    }
}
