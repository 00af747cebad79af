//! Straight-line code whose values are computed where they are first read.
//!
//! A solve that reads a matrix one column at a time (the factorization of
//! `M` from its tree's leaves) need not wait for every entry: [`interleaved`]
//! moves each statement of the code that builds the entries to just before
//! the first statement of the solve that reads what it binds (depth first,
//! in the order they were written). An entry then goes from the register
//! that computed it into the factorization, where otherwise every entry is
//! held, in a register or a slot of the stack, until the last is known.

use super::chunks::{idents, statements, Statement};
use super::tokens::concat;
use proc_macro2::TokenStream;
use std::collections::{HashMap, HashSet};

/// `inputs` then `consumers` (both straight-line statements), with each
/// statement of `inputs` moved to just before the first statement of
/// `consumers` that reads, directly or through other statements of
/// `inputs`, a name it binds. A statement of `inputs` that binds nothing
/// (a check that returns early) comes right after the last statement it
/// reads. What no consumer reads keeps its order after them. The two as
/// they are, one after the other, where either does not split into
/// statements or `inputs` binds a name twice.
pub(super) fn interleaved(inputs: TokenStream, consumers: TokenStream) -> TokenStream {
    let (Some(inputs_split), Some(consumers_split)) =
        (statements(inputs.clone()), statements(consumers.clone()))
    else {
        return concat([inputs, consumers]);
    };
    let Some(binder) = binders(&inputs_split) else {
        return concat([inputs, consumers]);
    };

    let reads = |s: &Statement| {
        let mut names = HashSet::new();
        idents(s.tokens.iter().cloned().collect(), &mut names);
        let mut found: Vec<usize> = names
            .iter()
            .filter_map(|n| binder.get(n).copied())
            .collect();
        found.sort_unstable();
        found
    };
    // A name read before the statement that binds it is an outer one.
    let needs: Vec<Vec<usize>> = inputs_split
        .iter()
        .enumerate()
        .map(|(i, s)| reads(s).into_iter().filter(|&d| d < i).collect())
        .collect();
    let mut order = Order::new(&inputs_split, &needs);
    let mut out = TokenStream::new();
    for check in order.ready_checks() {
        out.extend(inputs_split[check].tokens.iter().cloned());
    }
    for consumer in &consumers_split {
        // An input whose name the consumer binds again comes before it
        // (placed later, it would shadow the consumer's binding).
        let mut firsts = reads(consumer);
        firsts.extend(
            consumer
                .binds
                .iter()
                .filter_map(|(n, _)| binder.get(&n.to_string())),
        );
        for first in firsts {
            for i in order.place(first) {
                out.extend(inputs_split[i].tokens.iter().cloned());
            }
        }
        out.extend(consumer.tokens.iter().cloned());
    }
    for i in 0..inputs_split.len() {
        for i in order.place(i) {
            out.extend(inputs_split[i].tokens.iter().cloned());
        }
    }
    out
}

/// The statement that binds each name, `None` where one is bound twice
/// (moving statements could then change which binding a name reads).
fn binders(statements: &[Statement]) -> Option<HashMap<String, usize>> {
    let mut binder = HashMap::new();
    for (i, s) in statements.iter().enumerate() {
        for (name, _) in &s.binds {
            if binder.insert(name.to_string(), i).is_some() {
                return None;
            }
        }
    }
    Some(binder)
}

/// Which statements of the inputs are placed, and the checks (statements
/// that bind nothing) waiting for theirs.
struct Order<'a> {
    needs: &'a [Vec<usize>],
    placed: Vec<bool>,
    check: Vec<bool>,
    /// Per check, how many of its needs are not placed yet.
    waiting: Vec<usize>,
    /// Per statement, the checks that need it.
    watchers: Vec<Vec<usize>>,
}

impl<'a> Order<'a> {
    fn new(statements: &[Statement], needs: &'a [Vec<usize>]) -> Self {
        let check: Vec<bool> = statements.iter().map(|s| s.binds.is_empty()).collect();
        let mut watchers = vec![Vec::new(); statements.len()];
        for (c, n) in needs.iter().enumerate() {
            if check[c] {
                for &d in n {
                    watchers[d].push(c);
                }
            }
        }
        Order {
            needs,
            placed: vec![false; statements.len()],
            waiting: needs.iter().map(Vec::len).collect(),
            check,
            watchers,
        }
    }

    /// The checks that need nothing, placed.
    fn ready_checks(&mut self) -> Vec<usize> {
        let ready: Vec<usize> = (0..self.check.len())
            .filter(|&c| self.check[c] && self.waiting[c] == 0)
            .collect();
        for &c in &ready {
            self.placed[c] = true;
        }
        ready
    }

    /// Statement `root` after what it needs that is not placed yet, depth
    /// first, each statement's needs in the order they were written (on an
    /// explicit stack: a chain of thousands of statements is thousands
    /// deep), each check right after the last statement it needs: the
    /// statements to emit, in order.
    fn place(&mut self, root: usize) -> Vec<usize> {
        let mut out = Vec::new();
        if self.placed[root] {
            return out;
        }
        // (statement, how many of its needs have been visited)
        let mut stack = vec![(root, 0usize)];
        self.placed[root] = true;
        while let Some((i, next)) = stack.pop() {
            let needs = &self.needs[i];
            match needs[next..].iter().position(|&d| !self.placed[d]) {
                Some(offset) => {
                    let d = needs[next + offset];
                    stack.push((i, next + offset + 1));
                    self.placed[d] = true;
                    stack.push((d, 0));
                }
                None => {
                    out.push(i);
                    for &c in &self.watchers[i] {
                        self.waiting[c] -= 1;
                        if self.waiting[c] == 0 && !self.placed[c] {
                            self.placed[c] = true;
                            out.push(c);
                        }
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::interleaved;
    use quote::quote;

    fn text(tokens: proc_macro2::TokenStream) -> String {
        tokens.to_string().replace(' ', "")
    }

    /// Each input comes just before the first consumer that reads it,
    /// through what it reads itself (depth first, in written order); a
    /// check right after the last value it reads; what no consumer reads
    /// after them, in its order.
    #[test]
    fn inputs_come_where_they_are_first_read() {
        let inputs = quote! {
            let a = x * 2.0;
            let b = x + 1.0;
            let c = a * b;
            let d = x - 1.0;
            let e = d * d;
            if !(c.is_finite() & e.is_finite()) { return None; }
            let unread = x * 3.0;
        };
        let consumers = quote! {
            let p = e + 1.0;
            let r = c * p;
        };
        let out = text(interleaved(inputs, consumers));
        let expected = text(quote! {
            let d = x - 1.0;
            let e = d * d;
            let p = e + 1.0;
            let a = x * 2.0;
            let b = x + 1.0;
            let c = a * b;
            if !(c.is_finite() & e.is_finite()) { return None; }
            let r = c * p;
            let unread = x * 3.0;
        });
        assert_eq!(out, expected);
    }

    /// A name bound twice among the inputs leaves both parts as they
    /// are: moving a statement could change which binding a later one
    /// reads. An input whose name a consumer binds again, unread, comes
    /// before that consumer, which still shadows it.
    #[test]
    fn a_name_bound_twice_keeps_the_written_order() {
        let inputs = quote! {
            let a = x * 2.0;
            let a = a + 1.0;
            let b = x + 1.0;
        };
        let consumers = quote! { let p = b * a; };
        let out = text(interleaved(inputs.clone(), consumers.clone()));
        assert_eq!(out, text(quote!(#inputs #consumers)));
        let inputs = quote! {
            let a = x * 2.0;
            let b = x + 1.0;
        };
        let consumers = quote! { let p = b * 2.0; let a = p; };
        let out = text(interleaved(inputs, consumers));
        let expected = quote! {
            let b = x + 1.0;
            let p = b * 2.0;
            let a = x * 2.0;
            let a = p;
        };
        assert_eq!(out, text(expected));
    }
}
