//! Long straight-line bodies grouped into blocks, so that the nesting of
//! their `let`s stays bounded.
//!
//! Every `let` opens a lexical scope that lasts to the end of its block, so
//! a body of `m` consecutive `let`s is `m` scopes deep, and LLVM walks that
//! nesting recursively when it writes debug information (even line tables
//! only): the quadruped's generated solve (about 3,500 `let`s) overflowed
//! rustc's stack in `DwarfCompileUnit::createAndAddScopeChildren` in a
//! debug build. [`bounded`] groups the statements into blocks of at most
//! [`CHUNK`], each returning, as a tuple, the names it binds that later
//! code reads: the depth becomes at most `CHUNK` plus the number of blocks.
//! Optimized code is the same (the tuples are scalar values); bodies of up
//! to `CHUNK` statements are returned unchanged.

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use quote::quote;
use std::collections::HashSet;
use syn::Ident;

/// The most statements in one block.
pub(super) const CHUNK: usize = 512;

/// `code` (statements) with its statements grouped into blocks of at most
/// [`CHUNK`] (all but the last, whose `let`s stay in the caller's block),
/// each exporting the names that the later blocks or `tail` (the code
/// after it) read; `code` itself where it has no more than `CHUNK`
/// statements or does not split into statements ([`statements`]).
pub(super) fn bounded(code: TokenStream, tail: &TokenStream) -> TokenStream {
    let Some(stmts) = statements(code.clone()) else {
        return code;
    };
    if stmts.len() <= CHUNK {
        return code;
    }
    let chunks: Vec<&[Statement]> = stmts.chunks(CHUNK).collect();
    // What each chunk and everything after it read, from the end.
    let mut later: Vec<HashSet<String>> = vec![HashSet::new(); chunks.len()];
    let mut read = HashSet::new();
    idents(tail.clone(), &mut read);
    for (c, chunk) in chunks.iter().enumerate().rev() {
        later[c] = read.clone();
        for stmt in *chunk {
            idents(stmt.tokens.iter().cloned().collect(), &mut read);
        }
    }
    let last = chunks.len() - 1;
    let mut out = TokenStream::new();
    for (c, chunk) in chunks.iter().enumerate() {
        let tokens = chunk.iter().flat_map(|stmt| stmt.tokens.iter().cloned());
        if c == last {
            out.extend(tokens);
            break;
        }
        // The names bound here and read later, each at its last binding
        // (which decides its `mut`), in binding order: found from the end,
        // so that a name rebound many times is not searched for each time.
        let mut seen: HashSet<String> = HashSet::new();
        let mut bound: Vec<(Ident, bool)> = (chunk.iter().rev())
            .flat_map(|stmt| stmt.binds.iter().rev())
            .filter_map(|(name, mutable)| {
                let text = name.to_string();
                (later[c].contains(&text) && seen.insert(text)).then(|| (name.clone(), *mutable))
            })
            .collect();
        bound.reverse();
        let names = bound.iter().map(|(name, _)| name);
        let patterns = bound.iter().map(|(name, mutable)| {
            if *mutable {
                quote!(mut #name)
            } else {
                quote!(#name)
            }
        });
        let body: TokenStream = tokens.collect();
        out.extend(quote! {
            let (#(#patterns,)*) = {
                #body
                (#(#names,)*)
            };
        });
    }
    out
}

/// One statement of generated code, as its tokens, and the names it binds
/// (a `let`'s, with whether each is `mut`).
pub(super) struct Statement {
    pub(super) tokens: Vec<TokenTree>,
    pub(super) binds: Vec<(Ident, bool)>,
}

/// `code` split into statements on its tokens (parsing and printing the
/// body with syn cost a large model's expansion a tenth of its time): a
/// `let` ends at its `;`, an `if` at its last block (no `else` after it),
/// any other statement at a `;`. `None` for what does not split so (then
/// the body is left as it is).
pub(super) fn statements(code: TokenStream) -> Option<Vec<Statement>> {
    let mut out = Vec::new();
    let mut current: Vec<TokenTree> = Vec::new();
    let mut trees = code.into_iter().peekable();
    while let Some(tree) = trees.next() {
        let ends = match &tree {
            TokenTree::Punct(p) => p.as_char() == ';',
            TokenTree::Group(g) => {
                let is_if = matches!(current.first(), Some(TokenTree::Ident(i)) if i == "if");
                let else_follows = matches!(trees.peek(), Some(TokenTree::Ident(i)) if i == "else");
                g.delimiter() == Delimiter::Brace && is_if && !else_follows
            }
            _ => false,
        };
        current.push(tree);
        if ends {
            let binds = let_bindings(&current);
            out.push(Statement {
                tokens: std::mem::take(&mut current),
                binds,
            });
        }
    }
    current.is_empty().then_some(out)
}

/// The names a `let` statement's pattern binds (the tokens between `let`
/// and its `=`), and whether each is `mut`; none for other statements.
fn let_bindings(stmt: &[TokenTree]) -> Vec<(Ident, bool)> {
    let mut out = Vec::new();
    let Some((TokenTree::Ident(first), rest)) = stmt.split_first() else {
        return out;
    };
    if first != "let" {
        return out;
    }
    let pattern = rest.iter().take_while(
        |t| !matches!(t, TokenTree::Punct(p) if p.as_char() == '=' || p.as_char() == ':'),
    );
    pattern_names(pattern.cloned().collect(), &mut out);
    out
}

/// The identifiers of a pattern's tokens (`mut` marking the next one), `_`
/// left out.
fn pattern_names(tokens: TokenStream, out: &mut Vec<(Ident, bool)>) {
    let mut mutable = false;
    for tree in tokens {
        match tree {
            TokenTree::Ident(ident) if ident == "mut" => mutable = true,
            TokenTree::Ident(ident) => {
                if ident != "_" && ident != "ref" {
                    out.push((ident, mutable));
                }
                mutable = false;
            }
            TokenTree::Group(group) => pattern_names(group.stream(), out),
            TokenTree::Punct(_) | TokenTree::Literal(_) => {}
        }
    }
}

/// Every identifier in `tokens`, into `out`.
pub(super) fn idents(tokens: TokenStream, out: &mut HashSet<String>) {
    for tree in tokens {
        match tree {
            TokenTree::Ident(ident) => {
                out.insert(ident.to_string());
            }
            TokenTree::Group(group) => idents(group.stream(), out),
            TokenTree::Punct(_) | TokenTree::Literal(_) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use quote::ToTokens;

    /// A body of `CHUNK + 3` chained `let`s becomes a block of `CHUNK`
    /// exporting only the one name read later, then the three last `let`s.
    #[test]
    fn long_bodies_are_grouped_and_export_what_is_read_later() {
        let n = CHUNK + 3;
        let lets = (0..n).map(|i| {
            let name = quote::format_ident!("x{i}");
            if i == 0 {
                quote!(let #name = 1.0;)
            } else {
                let previous = quote::format_ident!("x{}", i - 1);
                quote!(let #name = #previous + 1.0;)
            }
        });
        let code = quote!(#(#lets)*);
        let last = quote::format_ident!("x{}", n - 1);
        let grouped = bounded(code, &quote!(#last));
        let stmts =
            syn::parse::Parser::parse2(syn::Block::parse_within, grouped).expect("statements");
        assert_eq!(stmts.len(), 4);
        let first = stmts[0].to_token_stream().to_string();
        let exported = format!("let (x{} ,) =", CHUNK - 1);
        assert!(first.starts_with(&exported), "{first}");
        let short = quote!(let a = 1.0; let b = a;);
        assert_eq!(
            bounded(short.clone(), &quote!(b)).to_string(),
            short.to_string()
        );
    }

    /// Statements split on their tokens: a tuple `let` with its names, an
    /// `if … else` as one statement, an assignment; a dangling expression
    /// leaves the body unsplit.
    #[test]
    fn statements_split_on_tokens() {
        let code = quote! {
            let (a, mut b, _) = (1.0, 2.0, 3.0);
            if a > b { return; } else { b = a; }
            b += 1.0;
        };
        let stmts = statements(code).expect("splits");
        assert_eq!(stmts.len(), 3);
        let names: Vec<(String, bool)> = stmts[0]
            .binds
            .iter()
            .map(|(n, m)| (n.to_string(), *m))
            .collect();
        assert_eq!(names, [("a".into(), false), ("b".into(), true)]);
        assert!(stmts[1].binds.is_empty() && stmts[2].binds.is_empty());
        assert!(statements(quote!(let a = 1.0; a + 1.0)).is_none());
    }
}
