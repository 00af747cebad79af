//! The loop over the Jacobian's columns, dispatched by their nonzero
//! patterns: each column's solve is emitted for the rows its right-hand
//! side can touch (a leg's joint moves its own leg's rows and its
//! ancestors' only; an arm's joint leaves the other arm's rows zero), and
//! columns of one pattern share one copy of it, chosen by a constant table.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// Which rows of `F̃` and of `b̃` a column's right-hand side can touch.
pub(super) type Pattern = (Vec<bool>, Vec<bool>);

/// The columns' dispatch: each group's code once, as one `match` arm.
pub(super) struct Dispatch {
    /// `const __GROUPS: [u16; columns] = [..];`, a structurally zero
    /// column's entry past the last group.
    pub table: TokenStream,
    /// `match __g { 0 => {..} .. _ => {..} }`.
    pub arms: TokenStream,
    /// The groups' patterns, in arm order.
    pub patterns: Vec<Pattern>,
}

/// The dispatch of the columns of `patterns` (an all-false pattern: a
/// structurally zero column, whose arm is `zero_arm`), `each` a pattern's code.
pub(super) fn dispatch(
    patterns: &[Pattern],
    each: &dyn Fn(&Pattern) -> TokenStream,
    zero_arm: &TokenStream,
) -> Dispatch {
    // Each distinct pattern's code once: its cost decides the groups, and
    // a group's is its arm.
    let mut codes: Vec<(&Pattern, TokenStream)> = Vec::new();
    for p in patterns.iter().filter(|p| nonzero(p)) {
        if !codes.iter().any(|(q, _)| *q == p) {
            codes.push((p, each(p)));
        }
    }
    let code_of = |p: &Pattern| codes.iter().find(|(q, _)| *q == p).map(|(_, c)| c.clone());
    let cost = |p: &Pattern| code_of(p).map_or(0, |c| operations(&c));
    let (groups, of_column) = groups(patterns, &cost);
    let zero = groups.len();
    let entries = of_column
        .iter()
        .map(|g| Literal::usize_unsuffixed(g.unwrap_or(zero)));
    let count = Literal::usize_unsuffixed(of_column.len());
    let arms = groups.iter().enumerate().map(|(id, pattern)| {
        let id = Literal::usize_unsuffixed(id);
        let body = code_of(pattern).unwrap_or_default();
        quote!(#id => { #body })
    });
    Dispatch {
        table: quote!(const __GROUPS: [u16; #count] = [#(#entries),*];),
        arms: quote! {
            match __g {
                #(#arms)*
                // A structurally zero column, or one written elsewhere.
                _ => { #zero_arm }
            }
        },
        patterns: groups,
    }
}

fn nonzero(p: &Pattern) -> bool {
    p.0.contains(&true) || p.1.contains(&true)
}

/// The arithmetic operators of some code: the estimated cost of a
/// column's solve.
fn operations(code: &TokenStream) -> usize {
    let text = code.to_string();
    [" * ", " + ", " - ", " / "]
        .iter()
        .map(|op| text.matches(op).count())
        .sum()
}

/// The columns' groups: each distinct nonzero pattern, solved by the
/// cheapest group whose pattern covers it where that costs at most a
/// quarter more than its own (a motor torque's column by its leg's), so
/// that few copies of the solve are emitted. Returns each group's pattern
/// and each column's group (`None`: structurally zero).
fn groups(
    patterns: &[Pattern],
    cost: &dyn Fn(&Pattern) -> usize,
) -> (Vec<Pattern>, Vec<Option<usize>>) {
    let mut distinct: Vec<(&Pattern, usize)> = Vec::new();
    for p in patterns.iter().filter(|p| nonzero(p)) {
        if !distinct.iter().any(|(q, _)| *q == p) {
            distinct.push((p, cost(p)));
        }
    }
    // The dearest first: a pattern's covering groups exist when it is placed.
    distinct.sort_by_key(|d| std::cmp::Reverse(d.1));
    let covers = |q: &Pattern, p: &Pattern| {
        let within = |a: &[bool], b: &[bool]| a.iter().zip(b).all(|(&x, &y)| !x || y);
        within(&p.0, &q.0) && within(&p.1, &q.1)
    };
    let mut groups: Vec<(Pattern, usize)> = Vec::new();
    let mut group_of: Vec<(&Pattern, usize)> = Vec::new();
    for (p, c) in distinct {
        let cheapest = (groups.iter().enumerate())
            .filter(|(_, (q, qc))| covers(q, p) && 4 * *qc <= 5 * c)
            .min_by_key(|(_, (_, qc))| *qc)
            .map(|(id, _)| id);
        let id = cheapest.unwrap_or_else(|| {
            groups.push((p.clone(), c));
            groups.len() - 1
        });
        group_of.push((p, id));
    }
    let of_column = patterns
        .iter()
        .map(|p| {
            let found = group_of.iter().find(|(q, _)| *q == p);
            found.map(|&(_, id)| id)
        })
        .collect();
    (groups.into_iter().map(|(p, _)| p).collect(), of_column)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(f: &[u8]) -> Pattern {
        (f.iter().map(|&x| x == 1).collect(), Vec::new())
    }

    #[test]
    fn columns_of_one_pattern_share_a_group_and_zero_columns_none() {
        let p = [
            pattern(&[1, 1, 0]),
            pattern(&[0, 0, 0]),
            pattern(&[1, 1, 0]),
        ];
        let cost = |p: &Pattern| p.0.iter().filter(|&&x| x).count() * 10;
        let (groups, of_column) = groups(&p, &cost);
        assert_eq!(groups, vec![pattern(&[1, 1, 0])]);
        assert_eq!(of_column, vec![Some(0), None, Some(0)]);
    }

    #[test]
    fn a_covered_pattern_joins_its_cover_only_when_that_costs_little_more() {
        // An arm's columns (rows 0..2) beside the waist's (rows 0..4): the
        // waist's solve costs twice the arm's, so the arm keeps its own;
        // a column missing one waist row costs nearly the waist's, so it
        // joins the waist's group.
        let p = [
            pattern(&[1, 1, 1, 1]),
            pattern(&[1, 1, 0, 0]),
            pattern(&[1, 1, 1, 0]),
        ];
        let cost = |p: &Pattern| match p.0.iter().filter(|&&x| x).count() {
            4 => 40,
            3 => 35,
            _ => 20,
        };
        let (groups, of_column) = groups(&p, &cost);
        assert_eq!(groups, vec![pattern(&[1, 1, 1, 1]), pattern(&[1, 1, 0, 0])]);
        assert_eq!(of_column, vec![Some(0), Some(1), Some(0)]);
    }
}
