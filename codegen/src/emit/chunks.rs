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

use proc_macro2::{TokenStream, TokenTree};
use quote::{quote, ToTokens};
use std::collections::HashSet;
use syn::{Ident, Pat, Stmt};

/// The most statements in one block.
pub(super) const CHUNK: usize = 512;

/// `code` (statements) with its statements grouped into blocks of at most
/// [`CHUNK`] (all but the last, whose `let`s stay in the caller's block),
/// each exporting the names that the later blocks or `tail` (the code
/// after it) read; `code` itself where it has no more than `CHUNK`
/// statements or does not parse as statements.
pub(super) fn bounded(code: TokenStream, tail: &TokenStream) -> TokenStream {
    let Ok(stmts) = syn::parse::Parser::parse2(syn::Block::parse_within, code.clone()) else {
        return code;
    };
    if stmts.len() <= CHUNK {
        return code;
    }
    let chunks: Vec<&[Stmt]> = stmts.chunks(CHUNK).collect();
    // What each chunk and everything after it read, from the end.
    let mut later: Vec<HashSet<String>> = vec![HashSet::new(); chunks.len()];
    let mut read = HashSet::new();
    idents(tail.clone(), &mut read);
    for (c, chunk) in chunks.iter().enumerate().rev() {
        later[c] = read.clone();
        for stmt in *chunk {
            idents(stmt.to_token_stream(), &mut read);
        }
    }
    let last = chunks.len() - 1;
    let mut out = TokenStream::new();
    for (c, chunk) in chunks.iter().enumerate() {
        if c == last {
            out.extend(chunk.iter().map(ToTokens::to_token_stream));
            break;
        }
        // The names bound here, last binding first wins, in binding order.
        let mut bound: Vec<(Ident, bool)> = Vec::new();
        for stmt in *chunk {
            if let Stmt::Local(local) = stmt {
                let mut names = Vec::new();
                bindings(&local.pat, &mut names);
                for (name, mutable) in names {
                    bound.retain(|(b, _)| *b != name);
                    bound.push((name, mutable));
                }
            }
        }
        bound.retain(|(name, _)| later[c].contains(&name.to_string()));
        let names = bound.iter().map(|(name, _)| name);
        let patterns = bound.iter().map(|(name, mutable)| {
            if *mutable {
                quote!(mut #name)
            } else {
                quote!(#name)
            }
        });
        out.extend(quote! {
            let (#(#patterns,)*) = {
                #(#chunk)*
                (#(#names,)*)
            };
        });
    }
    out
}

/// Every identifier in `tokens`, into `out`.
fn idents(tokens: TokenStream, out: &mut HashSet<String>) {
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

/// The names a `let` pattern binds, and whether each is `mut`.
fn bindings(pat: &Pat, out: &mut Vec<(Ident, bool)>) {
    match pat {
        Pat::Ident(p) => {
            out.push((p.ident.clone(), p.mutability.is_some()));
            if let Some((_, sub)) = &p.subpat {
                bindings(sub, out);
            }
        }
        Pat::Tuple(p) => p.elems.iter().for_each(|e| bindings(e, out)),
        Pat::Slice(p) => p.elems.iter().for_each(|e| bindings(e, out)),
        Pat::Type(p) => bindings(&p.pat, out),
        Pat::Reference(p) => bindings(&p.pat, out),
        Pat::Paren(p) => bindings(&p.pat, out),
        Pat::TupleStruct(p) => p.elems.iter().for_each(|e| bindings(e, out)),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
