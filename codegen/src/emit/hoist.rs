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
//! (`super::chunks`).

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
        let is_fn = matches!(&tokens[i], TokenTree::Ident(id) if id == "fn")
            && matches!(tokens.get(i + 1), Some(TokenTree::Ident(_)));
        if is_fn {
            // The signature up to the body; a declaration without one
            // ends at its `;`.
            while let Some(t) = tokens.get(i) {
                i += 1;
                match t {
                    TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => {
                        out.push(TokenTree::Group(hoisted(g)));
                        break;
                    }
                    TokenTree::Punct(p) if p.as_char() == ';' => {
                        out.push(t.clone());
                        break;
                    }
                    _ => out.push(t.clone()),
                }
            }
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

/// A group with the delimiter and span of `like` around `stream`.
fn regroup(like: &Group, stream: TokenStream) -> Group {
    let mut g = Group::new(like.delimiter(), stream);
    g.set_span(like.span());
    g
}
