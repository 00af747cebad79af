//! The `friction: [..]` section: Coulomb friction switched between stick
//! and slip (the runtime's `friction` module; the mathematics guide,
//! `docs/math.md`, "Stick–slip").
//!
//! An entry is written `coulomb(v, N, μs, μk)`, or `coulomb(v, N, μ)` for
//! `μs = μk`: `v` the sliding velocity, affine in the velocities
//! (`dot(x)`, `r * dot(theta) - dot(x)`, `dot(x) - belt`), `N` the normal
//! force, the coefficients constants (numbers and parameters). Each entry
//! adds a hidden mode field (`Sym::Param(first_mode + i)`, its sense
//! `s ∈ {−1, 0, 1}`) and, through it, two things the stages after this
//! one treat like any other:
//! - to the forces, the slip force `−μk N s ∂v/∂q̇` (zero when sticking);
//! - to the constraints, the stick row `(1 − s²) v = 0` (velocity level;
//!   a zero row when slipping, which the solve's rank rule drops).

use super::lower::Lowerer;
use super::Constraint;
use crate::expr::diff::Differentiator;
use crate::expr::{Graph, Id, Sym};
use crate::parse::List;
use proc_macro2::TokenStream;
use quote::ToTokens;
use syn::Expr;

/// One friction entry.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The sliding velocity `v(q, q̇, t)`.
    pub velocity: Id,
    /// `∂v/∂q̇ⱼ`, one per coordinate.
    pub jacobian: Vec<Id>,
    /// The normal force `N`.
    pub normal: Id,
    /// `μs`.
    pub mu_static: Id,
    /// `μk`.
    pub mu_kinetic: Id,
    /// The entry as written.
    pub tokens: TokenStream,
}

const FORM: &str = "a friction entry is written `coulomb(velocity, normal, mu_static, \
                    mu_kinetic)` or `coulomb(velocity, normal, mu)` (e.g. `coulomb(dot(x), m * g, 0.6, 0.4)`)";

impl Lowerer<'_> {
    /// The entries of `friction: [..]`, checked (a malformed one is
    /// reported and left out), their slip forces added to `forces` and
    /// their stick rows to `constraints` (`apply`).
    pub fn friction(
        &mut self,
        list: &List<Expr>,
        modes: &std::ops::Range<usize>,
        forces: &mut [Id],
        constraints: &mut Vec<Constraint>,
    ) -> Vec<Entry> {
        let mut d = Differentiator::new();
        let entries: Vec<Entry> = list
            .items
            .iter()
            .filter_map(|e| self.friction_entry(e, modes.end, &mut d))
            .collect();
        if entries.len() == list.items.len() {
            apply(self.graph, &entries, modes.start, forces, constraints);
        }
        entries
    }

    /// One entry, lowered and checked: its form, then its velocity and
    /// coefficients ([`Lowerer::usable`]), then the velocity affine in `q̇`.
    fn friction_entry(
        &mut self,
        e: &Expr,
        first_input: usize,
        d: &mut Differentiator,
    ) -> Option<Entry> {
        let [v, normal, mu_static, mu_kinetic] = self.coulomb_arguments(e)?;
        let before = self.errors.count();
        let lowered = [v, normal, mu_static, mu_kinetic].map(|x| self.lower(x));
        if self.errors.count() != before {
            return None;
        }
        let [velocity, normal_id, s_id, k_id] = lowered;
        let written = [(v, velocity), (mu_static, s_id), (mu_kinetic, k_id)];
        if !self.usable(written, first_input) {
            return None;
        }
        let jacobian: Vec<Id> = (0..self.n)
            .map(|j| d.partial(self.graph, velocity, Sym::Vel(j)))
            .collect();
        let g = &*self.graph;
        if jacobian
            .iter()
            .any(|&a| g.mentions(a, |s| matches!(s, Sym::Vel(_))))
        {
            self.errors.spanned(
                v,
                "a friction entry's velocity must be affine in the velocities \
                 (`J(q, t) q̇ + c(q, t)`, e.g. `dot(x)` or `r * dot(theta) - dot(x)`)",
            );
            return None;
        }
        Some(Entry {
            velocity,
            jacobian,
            normal: normal_id,
            mu_static: s_id,
            mu_kinetic: k_id,
            tokens: e.to_token_stream(),
        })
    }

    /// The four arguments of `coulomb(v, n, μs, μk)` (`μk = μs` where three
    /// are given); `None`, with an error, for any other form.
    fn coulomb_arguments<'e>(&mut self, e: &'e Expr) -> Option<[&'e Expr; 4]> {
        let args: Vec<&Expr> = match e {
            Expr::Call(call) if matches!(&*call.func, Expr::Path(p) if p.path.is_ident("coulomb")) => {
                call.args.iter().collect()
            }
            _ => {
                self.errors.spanned(e, FORM);
                return None;
            }
        };
        match args[..] {
            [v, n, s, k] => Some([v, n, s, k]),
            [v, n, mu] => Some([v, n, mu, mu]),
            _ => {
                let message = format!("{FORM}: this one has {} arguments", args.len());
                self.errors.spanned(e, message);
                None
            }
        }
    }

    /// Whether an entry's velocity involves a velocity and no input, and
    /// its coefficients are constants (`written`: the velocity, then both
    /// coefficients, as written and lowered); an error for the first that
    /// is not.
    fn usable(&mut self, written: [(&Expr, Id); 3], first_input: usize) -> bool {
        let [(v, velocity), coefficients @ ..] = written;
        let is_input = |s: Sym| matches!(s, Sym::Param(i) if i >= first_input);
        let g = &*self.graph;
        if !g.mentions(velocity, |s| matches!(s, Sym::Vel(_))) {
            self.errors.spanned(
                v,
                "a friction entry's velocity must involve a velocity (`dot(..)`): \
                 it is the sliding speed, held at zero while sticking",
            );
            return false;
        }
        if g.mentions(velocity, is_input) {
            self.errors.spanned(
                v,
                "a friction entry's velocity may not depend on control inputs \
                 (`inputs` appear in `forces` only)",
            );
            return false;
        }
        let constant = |s: Sym| matches!(s, Sym::Param(i) if i < first_input);
        for (mu, id) in coefficients {
            if g.mentions(id, |s| !constant(s)) {
                self.errors.spanned(
                    mu,
                    "a friction coefficient must be a constant: numbers and parameters",
                );
                return false;
            }
        }
        true
    }
}

/// Adds each entry's slip force `−μk N s ∂v/∂q̇` to `forces` and its stick
/// row `(1 − s²) v = 0` to `constraints`, `s` the entry's mode
/// (`Sym::Param(first_mode + i)`).
pub fn apply(
    graph: &mut Graph,
    entries: &[Entry],
    first_mode: usize,
    forces: &mut [Id],
    constraints: &mut Vec<Constraint>,
) {
    let one = graph.int(1);
    let two = graph.int(2);
    for (i, entry) in entries.iter().enumerate() {
        let s = graph.sym(Sym::Param(first_mode + i));
        let slip = graph.mul(&[entry.mu_kinetic, entry.normal, s]);
        let slip = graph.neg(slip);
        for (f, &a) in forces.iter_mut().zip(&entry.jacobian) {
            if graph.is_zero(a) {
                continue;
            }
            let term = graph.mul2(slip, a);
            *f = graph.add2(*f, term);
        }
        let s2 = graph.pow(s, two);
        let stuck = graph.sub(one, s2);
        let phi = graph.mul2(stuck, entry.velocity);
        constraints.push(Constraint {
            phi,
            level: super::Level::Velocity,
            tokens: entry.tokens.clone(),
            in_base: None,
            branch: None,
            rates: None,
        });
    }
}
