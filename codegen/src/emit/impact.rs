//! The methods of a system with gaps (`unilateral: [..]`): `GAPS`,
//! `gaps`, `gap_jacobian`, `gap_rates` and `impact`, the impulsive form of Gauss's
//! principle through the runtime's `impact::impact_with_gaps` (`docs/math.md`,
//! "Impacts"). Nothing is generated for a system without gaps.

use super::body::Body;
use super::context::{Context, Inputs};
use crate::expr::print::{Printer, Style};
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;

/// The gap methods, or nothing for a system without `unilateral`.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let gaps = &ctx.eq.system.unilateral;
    if gaps.is_empty() {
        return TokenStream::new();
    }
    let u = gaps.len();
    let u_lit = Context::dim(u);
    let params = ctx.params(Inputs::Positions);
    let (preamble, value) = gap_values(ctx);
    let (jpreamble, jvalue) = gap_gradients(ctx);
    let (gap_type, jac_type) = (ctx.vector(u), ctx.matrix(u, ctx.n));
    let written: Vec<String> = gaps.iter().map(|g| g.tokens.to_string()).collect();
    let list = written.join("`, `");
    let gaps_doc = format!(" The gaps `g(q)`, in the order written: `{list}`.");
    let state = ctx.params(Inputs::States);
    let impact = impact_method(ctx);
    let symbolic = symbolic(ctx);
    quote! {
        /// Number of gaps (`unilateral: [..]` entries).
        pub const GAPS: usize = #u_lit;

        /// The gaps and their gradients as text in sympy syntax.
        pub const SYMBOLIC_GAPS: ::constrained::SymbolicGaps = #symbolic;

        #[doc = #gaps_doc]
        /// Non-negative where the contacts are open.
        #[inline]
        pub fn gaps(&self, #params) -> #gap_type {
            #preamble
            #value
        }

        /// The gaps' gradients `∇g = ∂g/∂q`, one row per gap.
        #[inline]
        pub fn gap_jacobian(&self, #params) -> #jac_type {
            #jpreamble
            #jvalue
        }

        /// The gaps' rates `ġ = ∇g · q̇`, one per gap: given to the event
        /// location (`Events::with_rates`), they let it find a gap that
        /// closes and opens again between two points of its search grid.
        #[inline]
        pub fn gap_rates(&self, #state) -> #gap_type {
            self.gap_jacobian(q, t) * qd
        }

        #impact
    }
}

/// The body of `gaps`: its preamble and the vector of the gaps' values.
fn gap_values(ctx: &Context) -> (TokenStream, TokenStream) {
    let values: Vec<Id> = ctx.eq.system.unilateral.iter().map(|g| g.gap).collect();
    let body = Body::new(ctx.eq, &values);
    (
        body.preamble(),
        ctx.vector_value(values.iter().map(|&e| body.expr(e))),
    )
}

/// The body of `gap_jacobian`: its preamble and the matrix of the gaps'
/// gradients, one row per gap.
fn gap_gradients(ctx: &Context) -> (TokenStream, TokenStream) {
    let gaps = &ctx.eq.system.unilateral;
    let rows: Vec<&Vec<Id>> = gaps.iter().map(|g| &g.gradient).collect();
    let roots: Vec<Id> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    let jbody = Body::new(ctx.eq, &roots);
    let columns = (0..ctx.n)
        .map(|j| rows.iter().map(|r| jbody.expr(r[j])).collect())
        .collect();
    (jbody.preamble(), ctx.matrix_value(gaps.len(), columns))
}

/// The `impact` method, through the runtime's `impact::impact_with_gaps`.
fn impact_method(ctx: &Context) -> TokenStream {
    let u = ctx.eq.system.unilateral.len();
    let u_lit = Context::dim(u);
    let state = ctx.params(Inputs::States);
    let n_lit = Context::dim(ctx.n);
    let r_lit = Context::dim(ctx.k + u);
    let impact_type = ctx.path(quote!(Impact<T, #n_lit, #r_lit>));
    let result = ctx.result(impact_type, quote!(DynamicsError));
    let map = ctx.path(quote!(impact::impact_with_gaps));
    quote! {
        /// The impact map (the impulsive form of Gauss's principle): `q̇⁺`
        /// closest to `q̇⁻ = qd` in the metric of `M` such that each gap
        /// marked `active` rebounds by Newton's law,
        /// `∇gᵢ · q̇⁺ = −restitution[i] ∇gᵢ · q̇⁻`, while every constraint
        /// keeps its velocity-level residual at zero. The impulse's rows
        /// are the constraints first, then the gaps.
        #[inline]
        pub fn impact(
            &self,
            #state,
            active: [bool; #u_lit],
            restitution: [T; #u_lit],
        ) -> #result {
            #map(
                &self.mass_matrix(q, t),
                &self.constraint_matrices(q, qd, t).0,
                &self.constraint_velocity_residual(q, qd, t),
                &self.gap_jacobian(q, t),
                &active,
                &restitution,
                qd,
            )
        }
    }
}

/// The `SymbolicGaps` constant: each gap and its gradient's row, printed
/// as `SYMBOLIC` prints the constraints (sympy syntax, definitions
/// substituted), each expression whole.
fn symbolic(ctx: &Context) -> TokenStream {
    let sys = &ctx.eq.system;
    let coordinates: Vec<String> = sys.coordinates.iter().map(ToString::to_string).collect();
    let parameters: Vec<String> = sys.parameters.iter().map(ToString::to_string).collect();
    let p = Printer::new(&sys.graph, &coordinates, &parameters, Style::Sympy);
    let gaps = sys.unilateral.iter().map(|g| p.print(g.gap));
    let rows = sys.unilateral.iter().map(|g| {
        let entries = g.gradient.iter().map(|&e| p.print(e));
        quote! { &[#(#entries),*] }
    });
    quote! {
        ::constrained::SymbolicGaps {
            gaps: &[#(#gaps),*],
            gap_jacobian: &[#(#rows),*],
        }
    }
}
