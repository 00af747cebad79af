//! A bound on how deeply the input nests, checked on the raw tokens before
//! anything recursive sees them.
//!
//! syn's parser, the lowering of expressions and rustc's handling of the
//! output all recurse once per level of nesting: 1,000 nested parentheses,
//! or a unary minus repeated 20,000 times, overflow the stack of the thread
//! that runs the macro (rustc's, 8 MiB). A macro must not crash its
//! compiler, so input nested deeper than [`MAX_DEPTH`] is a spanned error.
//!
//! The bound is computed without recursion. An expression's syntax tree is
//! at most as deep as, along any path of nested groups, the operators of
//! each comma-separated segment plus one per group: every binary or unary
//! operator and every `.method()` adds at most one level, and calls and
//! parentheses are groups. Commas and semicolons separate list items, which
//! do not nest, so a long list of definitions costs nothing. Real models
//! stay far below the bound (the reference models and the 32-link chain
//! stay within 24, a test checks): long formulas belong in `definitions`, which are not nested.

use proc_macro2::{Span, TokenStream, TokenTree};

/// The deepest nesting accepted (a bound on the depth of any expression's
/// syntax tree, module docs).
pub const MAX_DEPTH: usize = 256;

/// One open group: its remaining tokens and the running costs.
struct Frame {
    tokens: proc_macro2::token_stream::IntoIter,
    /// Operators in the current segment so far.
    operators: usize,
    /// The costliest group in the current segment so far.
    nested: usize,
    /// The costliest segment of the group so far.
    worst: usize,
    /// The current segment's first token, for the error's span.
    segment_start: Option<Span>,
}

impl Frame {
    fn new(stream: TokenStream) -> Frame {
        Frame {
            tokens: stream.into_iter(),
            operators: 0,
            nested: 0,
            worst: 0,
            segment_start: None,
        }
    }

    fn close_segment(&mut self) {
        self.worst = self.worst.max(self.operators + self.nested);
        self.operators = 0;
        self.nested = 0;
        self.segment_start = None;
    }
}

/// `Err` pointing at the first segment whose nesting exceeds [`MAX_DEPTH`].
pub fn check(input: &TokenStream) -> syn::Result<()> {
    check_at_most(input, MAX_DEPTH)
}

/// [`check`] with the bound `max` instead of [`MAX_DEPTH`].
fn check_at_most(input: &TokenStream, max: usize) -> syn::Result<()> {
    let too_deep = |span| too_deep(span, max);
    let mut stack = vec![Frame::new(input.clone())];
    loop {
        let Some(frame) = stack.last_mut() else {
            return Ok(());
        };
        match frame.tokens.next() {
            Some(token) => {
                if frame.segment_start.is_none() {
                    frame.segment_start = Some(token.span());
                }
                match token {
                    TokenTree::Punct(p) if matches!(p.as_char(), ',' | ';') => {
                        frame.close_segment()
                    }
                    TokenTree::Punct(p) if p.as_char() != ':' => frame.operators += 1,
                    TokenTree::Group(g) => {
                        let span = g.span();
                        stack.push(Frame::new(g.stream()));
                        if stack.len() > max {
                            return Err(too_deep(span));
                        }
                    }
                    _ => {}
                }
                let frame = stack.last().expect("just pushed or present");
                if frame.operators + frame.nested > max {
                    return Err(too_deep(
                        frame.segment_start.unwrap_or_else(Span::call_site),
                    ));
                }
            }
            None => {
                let mut done = stack.pop().expect("non-empty");
                done.close_segment();
                if let Some(parent) = stack.last_mut() {
                    parent.nested = parent.nested.max(done.worst + 1);
                    if parent.operators + parent.nested > max {
                        let at = parent.segment_start.unwrap_or_else(Span::call_site);
                        return Err(too_deep(at));
                    }
                }
            }
        }
    }
}

fn too_deep(span: Span, max: usize) -> syn::Error {
    syn::Error::new(
        span,
        format!(
            "this expression nests more than {max} levels deep (operators, method calls \
             and parentheses); name its parts in `definitions` to flatten it"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn depth_ok(text: &str) -> bool {
        check(&text.parse().expect("tokens")).is_ok()
    }

    #[test]
    fn the_fixtures_are_far_below_the_bound() {
        for links in [1, 8, 32] {
            let text = crate::tools::fixtures::planar_chain("Chain", links);
            let tokens: TokenStream = text.parse().expect("tokens");
            let body = tokens.into_iter().last().expect("the macro's braces");
            let TokenTree::Group(g) = body else {
                panic!("no body")
            };
            check_at_most(&g.stream(), 24).expect("within 24");
        }
    }

    #[test]
    fn long_lists_are_not_nesting() {
        let defs: Vec<String> = (0..5000).map(|i| format!("d{i} = x * {i}.0 + y")).collect();
        assert!(depth_ok(&format!("definitions: [{}]", defs.join(", "))));
    }

    #[test]
    fn deep_parentheses_unary_chains_and_method_chains_are_bounded() {
        let parens = format!("{}x{}", "(".repeat(300), ")".repeat(300));
        assert!(!depth_ok(&format!("forces: [{parens}]")));
        assert!(!depth_ok(&format!("forces: [{}x]", "-".repeat(300))));
        assert!(!depth_ok(&format!("forces: [x{}]", ".sin()".repeat(300))));
        assert!(depth_ok(&format!("forces: [x{}]", ".sin()".repeat(200))));
        assert!(depth_ok(&format!(
            "forces: [{}x{}]",
            "(".repeat(200),
            ")".repeat(200)
        )));
    }

    #[test]
    fn a_hundred_thousand_nested_groups_do_not_overflow_the_check() {
        let parens = format!("{}x{}", "(".repeat(100_000), ")".repeat(100_000));
        let err = check(&parens.parse().expect("tokens")).expect_err("too deep");
        assert!(err.to_string().contains("nests more than"));
    }
}
