//! The impl of the runtime's hidden `Generated` trait: the inherent
//! methods, forwarded, so that the runtime's blanket impl provides
//! `ConstrainedSystem` (the `State`-taking methods) once for every system.
//!
//! [`FORWARDS`] lists what every system forwards, and a row of
//! `EVALUATIONS` (`emit/dynamics.rs`) marked `forwarded` adds itself;
//! each of them but `gauss` is a row of the runtime's table
//! (`forwarded_methods!` in `runtime/src/methods.rs`), which declares the
//! trait methods. So a new evaluation reaches `ConstrainedSystem` by its
//! row of `EVALUATIONS` here and one row there.

use super::context::{Context, Inputs};
use super::dynamics;
use super::mass_inverse;
use crate::equations::mass_inverse::MassInverse;
use proc_macro2::{Span, TokenStream};
use quote::quote;

/// One method of `Generated` and how it is forwarded.
#[derive(Clone, Copy)]
struct Forward {
    /// The method's name, the inherent method's and the trait's.
    name: &'static str,
    /// Its arguments after `&self`.
    args: Inputs,
    /// What it returns.
    returns: Returns,
}

/// What a forwarded method returns.
#[derive(Clone, Copy)]
enum Returns {
    /// The inherent method's value, whose type this gives.
    Same(fn(&Context) -> TokenStream),
    /// A row of `EVALUATIONS` marked `forwarded`, where the system has
    /// it: `Some` of its value as a `Result` (`Ok` of a total method's);
    /// the runtime's default `None` where the system does not.
    Evaluation,
    /// The solver `gauss`, asked for `(q̈, Aᵀλ)` as a `Result`.
    Gauss,
}

/// The methods of `Generated` that every system provides (besides the
/// projection step, `mass_inverse::step`), in the order they are emitted;
/// the `forwarded` rows of `EVALUATIONS` follow them ([`forwards`]).
const FORWARDS: &[Forward] = &[
    Forward {
        name: "mass_matrix",
        args: Inputs::Positions,
        returns: Returns::Same(|c| c.matrix(c.n, c.n)),
    },
    Forward {
        name: "forces",
        args: Inputs::States,
        returns: Returns::Same(|c| c.vector(c.n)),
    },
    Forward {
        name: "constraint_residual",
        args: Inputs::States,
        returns: Returns::Same(|c| c.vector(c.k)),
    },
    Forward {
        name: "constraint_velocity_residual",
        args: Inputs::States,
        returns: Returns::Same(|c| c.vector(c.k)),
    },
    Forward {
        name: "constraint_matrices",
        args: Inputs::States,
        returns: Returns::Same(|c| {
            let (a, b) = (c.matrix(c.k, c.n), c.vector(c.k));
            quote!((#a, #b))
        }),
    },
    Forward {
        name: "gauss",
        args: Inputs::States,
        returns: Returns::Gauss,
    },
    Forward {
        name: "gibbs_appell_matrices",
        args: Inputs::States,
        returns: Returns::Same(|c| {
            let (m, v) = (c.matrix(c.n, c.n), c.vector(c.n));
            c.result(quote!((#m, #v)), quote!(GibbsAppellError))
        }),
    },
    Forward {
        name: "acceleration_gibbs_appell",
        args: Inputs::States,
        returns: Returns::Same(|c| c.result(c.vector(c.n), quote!(GibbsAppellError))),
    },
];

/// Every forwarded method: the rows of [`FORWARDS`], then the rows of
/// `EVALUATIONS` marked `forwarded` (those taking `(q, t)` or
/// `(q, qd, t)`; the runtime's table has no other arguments).
fn forwards() -> impl Iterator<Item = Forward> {
    let evaluations = dynamics::EVALUATIONS
        .iter()
        .filter(|e| e.forwarded)
        .filter_map(|e| {
            let args = match e.args {
                dynamics::Args::Positions => Inputs::Positions,
                dynamics::Args::States => Inputs::States,
                dynamics::Args::Accelerations => return None,
            };
            Some(Forward {
                name: e.name,
                args,
                returns: Returns::Evaluation,
            })
        });
    FORWARDS.iter().copied().chain(evaluations)
}

/// One row's method, or nothing for an evaluation the system lacks.
fn forward(ctx: &Context, row: &Forward) -> Option<TokenStream> {
    let name = syn::Ident::new(row.name, Span::call_site());
    let (params, args) = (ctx.params(row.args), ctx.args(row.args));
    let (ret, body) = match row.returns {
        Returns::Same(ret) => (ret(ctx), quote!(Self::#name(self, #args))),
        Returns::Evaluation => {
            let ok = dynamics::value_type(ctx, row.name)?;
            let value = quote!(Self::#name(self, #args));
            let value = if ctx.eq.mass_inverse.fallible() {
                value
            } else {
                quote!(::core::result::Result::Ok(#value))
            };
            let ret = ctx.result(ok, quote!(DynamicsError));
            (
                quote!(::core::option::Option<#ret>),
                quote!(::core::option::Option::Some(#value)),
            )
        }
        Returns::Gauss => {
            let n = Context::dim(ctx.n);
            let motion = ctx.private(quote!(Motion<T, #n>));
            let ret = ctx.result(motion, quote!(DynamicsError));
            let correction = ctx.correction_type();
            let body = ctx.call_gauss("Fallible", quote!(correction));
            let only = ctx.call_gauss("FallibleAcceleration", quote!(correction));
            let acceleration = ctx.result(
                quote!(::constrained::nalgebra::SVector<T, #n>),
                quote!(DynamicsError),
            );
            let k = Context::dim(ctx.k);
            let multiplied_finish = ctx.private(quote!(Multiplied<#k>));
            let call_args = ctx.args(Inputs::States);
            let with =
                quote!(self.gauss::<#multiplied_finish>(#call_args, ::core::option::Option::None));
            let reaction = ctx.private(quote!(Reaction<T, #n, #k>));
            let multiplied = ctx.result(
                quote!((::constrained::nalgebra::SVector<T, #n>, #reaction)),
                quote!(DynamicsError),
            );
            return Some(quote! {
                #[inline]
                fn gauss(&self, #params, correction: #correction) -> #ret { #body }
                #[inline]
                fn gauss_acceleration(&self, #params, correction: #correction) -> #acceleration {
                    #only
                }
                #[inline]
                fn gauss_multipliers(&self, #params) -> #multiplied { #with }
            });
        }
    };
    Some(quote! {
        #[inline]
        fn #name(&self, #params) -> #ret { #body }
    })
}

/// The impl of `constrained::__private::Generated` for the system.
pub(super) fn generated_impl(ctx: &Context) -> TokenStream {
    let name = &ctx.eq.system.name;
    let (n, k) = (Context::dim(ctx.n), Context::dim(ctx.k));
    let generated = ctx.private(quote!(Generated<T, #n, #k>));
    let level = ctx.path(quote!(ConstraintLevel));
    let methods = forwards().filter_map(|row| forward(ctx, &row));
    let step = mass_inverse::step(ctx);
    let semidefinite = matches!(ctx.eq.mass_inverse, MassInverse::Auxiliary(_)).then(|| {
        quote!(
            const SEMIDEFINITE_MASS: bool = true;
        )
    });
    let generic_rank = (ctx.generic_rank < ctx.k).then(|| {
        let r = Context::dim(ctx.generic_rank);
        quote!(
            const GENERIC_RANK: usize = #r;
        )
    });
    quote! {
        impl<T: ::constrained::nalgebra::RealField + Copy> #generated for #name<T> {
            const CONSTRAINT_LEVELS: [#level; #k] = Self::CONSTRAINT_LEVELS;
            #semidefinite
            #generic_rank
            #(#methods)*
            #step
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{forwards, Returns};
    use crate::emit::dynamics::{Args, EVALUATIONS};

    /// Every forwarded method but `gauss` is a row of the runtime's table,
    /// with the same arguments, and every row there is one here.
    #[test]
    fn forwards_match_the_runtime_table() {
        let table = include_str!("../../../runtime/src/methods.rs");
        // `kind [#[attributes]] fn name(args) -> ..`, read as `kind fn name(args)..`.
        let rows: Vec<String> = table
            .lines()
            .map(str::trim)
            .filter(|l| l.starts_with("required ") || l.starts_with("optional "))
            .filter_map(|l| Some(format!("{} {}", &l[..8], &l[l.find("fn ")?..])))
            .collect();
        let forwarded: Vec<super::Forward> = forwards()
            .filter(|f| !matches!(f.returns, Returns::Gauss))
            .collect();
        let marked = EVALUATIONS.iter().filter(|e| e.forwarded);
        assert!(
            marked.clone().all(|e| e.args != Args::Accelerations),
            "the runtime's table takes no accelerations"
        );
        assert_eq!(
            forwarded
                .iter()
                .filter(|f| matches!(f.returns, Returns::Evaluation))
                .count(),
            marked.count()
        );
        assert_eq!(rows.len(), forwarded.len(), "{rows:?}");
        for f in forwarded {
            let args = match f.args {
                super::Inputs::Positions => "(q, t)",
                super::Inputs::States => "(q, qd, t)",
            };
            let kind = match f.returns {
                Returns::Evaluation => "optional",
                _ => "required",
            };
            let row = format!("{kind} fn {}{args}", f.name);
            assert!(
                rows.iter().any(|r| r.starts_with(&row)),
                "{row} not in methods.rs"
            );
        }
    }
}
