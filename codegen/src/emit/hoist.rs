//! Each constant a generated function reads more than once, bound once
//! at its top.
//!
//! The emitter marks a constant where it is used (`super::literal`), and
//! this pass writes each mark out: as the name it is bound to, or, read
//! once, as the call `::constrained::__private::lit::<T>(0.5f64)` in
//! place. A large model's methods read tens of thousands of constants:
//! 31,538 in the standing G1's expansion, 3,385 distinct within their
//! function. Each is a call of a generic function that the compiler
//! type-checks, borrow-checks and lowers on its own, a basic block of
//! every later pass;
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

use super::literal::literal_call;
use proc_macro2::{Delimiter, Group, Ident, Literal, Punct, Span, TokenStream, TokenTree};
use quote::{format_ident, quote};
use std::collections::HashMap;

/// `items` with every function body's constants bound at its top
/// ([`hoisted`]); the other tokens as they are, but for a constant's mark
/// outside any function, which nothing binds: written out in place.
pub(super) fn literals(items: TokenStream) -> TokenStream {
    let mut out = Vec::new();
    let none_bound = HashMap::new();
    replaced(
        taken_apart(items),
        &none_bound,
        &mut HashMap::new(),
        &mut Vec::new(),
        &mut out,
    );
    out.into_iter().collect()
}

/// A token tree taken apart by value, once, for the two walks over a
/// body (counting its constants, then replacing them). The walks cannot
/// read a `TokenStream` in place: iterating one whose tokens a `Group`
/// still shares copies every token, each identifier and literal its own
/// allocation, which would be most of this pass's cost.
enum Tree {
    /// Where a tree was, after it was moved out to be emitted.
    Moved,
    /// An identifier, punctuation character or literal.
    Leaf(TokenTree),
    /// A delimited group, its span kept for error messages.
    Group(Delimiter, Span, Vec<Tree>),
}

/// `stream`'s trees, each group's tokens moved out of it: once the group
/// is dropped its stream is the only owner, and iterates without copying.
fn taken_apart(stream: TokenStream) -> Vec<Tree> {
    stream
        .into_iter()
        .map(|token| match token {
            TokenTree::Group(group) => {
                let (delimiter, span) = (group.delimiter(), group.span());
                let inner = group.stream();
                drop(group);
                Tree::Group(delimiter, span, taken_apart(inner))
            }
            leaf => Tree::Leaf(leaf),
        })
        .collect()
}

/// `tree` as a token, moved into `out` (nothing where it was moved before).
fn put_back(tree: Tree, out: &mut Vec<TokenTree>) {
    match tree {
        Tree::Moved => {}
        Tree::Leaf(leaf) => out.push(leaf),
        Tree::Group(delimiter, span, children) => {
            let mut inner = Vec::with_capacity(children.len());
            children.into_iter().for_each(|c| put_back(c, &mut inner));
            out.push(regroup(delimiter, span, inner));
        }
    }
}

/// A function body with each constant it reads more than once replaced
/// by `__lit{k}`, in the order they first appear, bound by one statement
/// before the rest. A constant read once stays where it is: binding it
/// would spare no call, and the number reads better in place.
fn hoisted(body: Vec<Tree>) -> Vec<TokenTree> {
    let mut reads: HashMap<String, usize> = HashMap::new();
    count(&body, &mut reads);
    let mut names: HashMap<String, Ident> = HashMap::new();
    let mut bound: Vec<(Ident, TokenStream)> = Vec::new();
    let mut stream = Vec::with_capacity(body.len());
    replaced(body, &reads, &mut names, &mut bound, &mut stream);
    if bound.is_empty() {
        return stream;
    }
    let (idents, values): (Vec<Ident>, Vec<TokenStream>) = bound.into_iter().unzip();
    let length = Literal::usize_unsuffixed(idents.len());
    let binding = quote! {
        let [#(#idents),*]: [T; #length] = [#(#values),*];
    };
    let mut out: Vec<TokenTree> = binding.into_iter().collect();
    out.extend(stream);
    out
}

/// How many times `trees` read each constant, by its literal's text.
fn count(trees: &[Tree], reads: &mut HashMap<String, usize>) {
    let mut i = 0;
    while i < trees.len() {
        if let Some(end) = function_at(trees, i) {
            i = end;
            continue;
        }
        if let Some(value) = constant_at(&trees[i]) {
            *reads.entry(value.key()).or_insert(0) += 1;
        } else if let Tree::Group(_, _, children) = &trees[i] {
            count(children, reads);
        }
        i += 1;
    }
}

/// `trees` into `out`, each constant's mark written out as the call
/// `::constrained::__private::lit::<T>(c)` where it is read once; where
/// `reads` counts it more than once, replaced by the name of `c`, a new
/// one (with the call it stands for) appended to `bound` on first sight.
fn replaced(
    mut trees: Vec<Tree>,
    reads: &HashMap<String, usize>,
    names: &mut HashMap<String, Ident>,
    bound: &mut Vec<(Ident, TokenStream)>,
    out: &mut Vec<TokenTree>,
) {
    let mut i = 0;
    while i < trees.len() {
        // A function defined in the body (`__leg_share`) is an item, which
        // cannot read the body's bindings: it binds its own constants (and
        // `count` leaves its reads out of the body's).
        if let Some(end) = function_at(&trees, i) {
            function(&mut trees[i..end], out);
            i = end;
            continue;
        }
        if let Some(value) = constant_at(&trees[i]) {
            let key = value.key();
            if reads.get(&key).is_some_and(|&n| n > 1) {
                let name = names.entry(key).or_insert_with(|| {
                    let name = format_ident!("__lit{}", bound.len(), span = Span::call_site());
                    bound.push((name.clone(), value.call()));
                    name
                });
                out.push(TokenTree::Ident(name.clone()));
            } else {
                out.extend(value.call());
            }
            i += 1;
            continue;
        }
        match std::mem::replace(&mut trees[i], Tree::Moved) {
            Tree::Group(delimiter, span, children) => {
                let mut inner = Vec::with_capacity(children.len());
                replaced(children, reads, names, bound, &mut inner);
                out.push(regroup(delimiter, span, inner));
            }
            other => put_back(other, out),
        }
        i += 1;
    }
}

/// Where `tree` is a constant's mark (`super::literal`), its value: a
/// literal, after a `-` where it is negative (a stream splits a negative
/// literal in two).
fn constant_at(tree: &Tree) -> Option<Constant<'_>> {
    match tree {
        Tree::Group(Delimiter::None, _, inner) => match inner.as_slice() {
            [Tree::Leaf(TokenTree::Literal(value))] => Some(Constant { minus: None, value }),
            [Tree::Leaf(TokenTree::Punct(minus)), Tree::Leaf(TokenTree::Literal(value))]
                if minus.as_char() == '-' =>
            {
                Some(Constant {
                    minus: Some(minus),
                    value,
                })
            }
            _ => None,
        },
        _ => None,
    }
}

/// A constant's value as its mark holds it ([`constant_at`]).
struct Constant<'a> {
    minus: Option<&'a Punct>,
    value: &'a Literal,
}

impl Constant<'_> {
    /// The text by which reads of one constant are counted together.
    fn key(&self) -> String {
        match self.minus {
            Some(_) => format!("-{}", self.value),
            None => self.value.to_string(),
        }
    }

    /// The call the mark stands for, `lit::<T>(c)`.
    fn call(&self) -> TokenStream {
        let (minus, value) = (self.minus, self.value);
        literal_call(quote!(#minus #value))
    }
}

/// Where `trees[i..]` is a function item (`fn name … { … }`, or a
/// declaration, which ends at its `;`), the position just past it;
/// `None` elsewhere.
fn function_at(trees: &[Tree], i: usize) -> Option<usize> {
    let is_fn = matches!(&trees[i], Tree::Leaf(TokenTree::Ident(id)) if id == "fn")
        && matches!(trees.get(i + 1), Some(Tree::Leaf(TokenTree::Ident(_))));
    if !is_fn {
        return None;
    }
    let last = trees[i..].iter().position(|t| match t {
        Tree::Group(delimiter, _, _) => *delimiter == Delimiter::Brace,
        Tree::Leaf(TokenTree::Punct(p)) => p.as_char() == ';',
        _ => false,
    })?;
    Some(i + last + 1)
}

/// The function item `trees` ([`function_at`]), moved into `out`, its
/// body's constants bound at its top ([`hoisted`]).
fn function(trees: &mut [Tree], out: &mut Vec<TokenTree>) {
    let Some((last, signature)) = trees.split_last_mut() else {
        return;
    };
    signature
        .iter_mut()
        .for_each(|t| put_back(std::mem::replace(t, Tree::Moved), out));
    match std::mem::replace(last, Tree::Moved) {
        Tree::Group(Delimiter::Brace, span, body) => {
            out.push(regroup(Delimiter::Brace, span, hoisted(body)));
        }
        other => put_back(other, out),
    }
}

/// A group of `delimiter` and `span` around `tokens`.
fn regroup(delimiter: Delimiter, span: Span, tokens: Vec<TokenTree>) -> TokenTree {
    let mut group = Group::new(delimiter, tokens.into_iter().collect());
    group.set_span(span);
    TokenTree::Group(group)
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
        let lit = |x: f64| crate::emit::body::literal(crate::expr::num::Num::Float(x)).0;
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

    /// A negative constant, which a stream splits into `-` and a literal,
    /// is counted and bound with its sign, apart from its magnitude.
    #[test]
    fn a_negative_constant_keeps_its_sign() {
        let lit = |x: f64| crate::emit::body::literal(crate::expr::num::Num::Float(x)).0;
        let (minus, plus) = (lit(-4.5), lit(4.5));
        let out = literals(quote! {
            fn f<T>() -> T { #minus * #minus + #plus }
        })
        .to_string();
        assert!(
            out.contains(
                "let [__lit0] : [T ; 1] = [:: constrained :: __private :: lit :: < T > (- 4.5f64)]"
            ),
            "{out}"
        );
        assert!(
            out.contains("__lit0 * __lit0 + :: constrained :: __private :: lit :: < T > (4.5f64)"),
            "{out}"
        );
    }
}
