//! Stage 4: [`Equations`] → Rust tokens.
//!
//! Every generated function is straight-line code: bind the variables it
//! uses, compute the shared subexpressions chosen by `expr::cse::Schedule` in
//! topological order, and build a fixed-size nalgebra result from an array.
//! Nothing allocates, indexes or panics; literals go through
//! `::constrained::__private::lit` so one body serves `f32` and `f64`.
//!
//! Two axes, one per level:
//!
//! - the files here are the generated methods (`motion`: `acceleration`,
//!   `constraint_force`; `jacobian`: the linearization; `dynamics`: the
//!   evaluations; `gibbs_appell`, `tangent`; `forwards`: the impl of the
//!   runtime's trait, from one table), and the shared value of the
//!   solve (`solve`: `checked_motion`, `corrected`);
//! - `mass_inverse/` holds one module per way of applying `M⁻¹`
//!   (`symbolic`, `factored`, the latter also through a semi-definite `M`'s
//!   auxiliary mass), each with its solver, Jacobian and step; its `mod.rs` is the only `match` on the strategy.
//!
//! Below both: `body` (expressions to tokens), `hoist` (a method's
//! repeated constants bound once), `dispatch` (large functions copied for
//! `dispatch: [avx]`), `detached` (a large model's values as
//! free functions), `chunks` (long bodies in
//! blocks), `context` (types, names, signatures), `ldlt` (the structured
//! factorization), `subproducts` and `reuse` (the products a body shares).

mod body;
mod chunks;
mod context;
mod demand;
pub mod derivation;
mod derivation_bodies;
mod derivation_saddle;
mod detached;
mod dispatch;
mod dynamics;
mod forwards;
mod frames;
mod friction;
mod gibbs_appell;
mod hoist;
mod impact;
mod jacobian;
mod ldlt;
mod literal;
mod mass_inverse;
mod motion;
mod reuse;
mod solve;
mod subproducts;
mod tangent;
mod tokens;

use crate::equations::Equations;
use crate::expr::print::{shared_subexpressions, Printer, Style};
use crate::expr::Id;
use body::{Body, Stores};
use context::{Context, Inputs};
use proc_macro2::TokenStream;
use quote::quote;
use std::collections::HashMap;
use syn::Ident;

pub use crate::expr::POWER_METHODS;

/// Emits the struct, its constants and its functions.
pub fn system(eq: &Equations) -> TokenStream {
    let partition = &eq.partition;
    let ctx = Context::new(eq, partition.rank);
    let sys = &eq.system;
    let name = &sys.name;
    let (methods, functions) = inherent_methods(&ctx);
    let friction_impl = friction::trait_impl(&ctx);
    // A model read from a file is rebuilt when the file changes.
    let files = sys.bodies.iter().flat_map(|b| &b.files).map(|f| {
        quote! {
            const _: &[u8] = ::core::include_bytes!(#f);
        }
    });
    let tangent_impl = eq.jacobians.then(|| jacobian::tangent_impl(&ctx));
    let generated_impl = forwards::generated_impl(&ctx);
    let derivation = derivation::text(eq, partition);
    let definition = struct_definition(sys, ctx.n, ctx.k, &derivation_doc(&derivation));
    let constants = constants(&ctx, &derivation);

    // Every method's constants bound once, at its top (`hoist`); then the
    // large ones copied for the extensions of `dispatch` (`dispatch`).
    let extensions = &sys.dispatch;
    let methods = dispatch::methods(hoist::literals(methods), extensions);
    let impls = hoist::literals(quote! { #generated_impl #tangent_impl #friction_impl });
    let impls = dispatch::items(impls, extensions);
    let functions = functions.map(|f| dispatch::items(f, extensions));
    quote! {
        #definition

        #[allow(unused_variables, non_snake_case, clippy::all, clippy::pedantic)]
        impl<T: ::constrained::nalgebra::RealField + Copy> #name<T> {
            #constants

            #methods
        }

        #functions

        #(#files)*

        #impls
    }
}

/// The inherent methods, in the order they are emitted: the model's own
/// values, `A` and `b`, the solves, the Gibbs–Appell form, the
/// linearization, the evaluations, the gaps' and friction's; and the
/// functions the first two forward to (`detached`).
fn inherent_methods(ctx: &Context) -> (TokenStream, Option<TokenStream>) {
    let mut detached = model_values(ctx);
    detached.push(constraint_matrices(ctx));
    let values = detached.iter().map(|d| &d.method);
    let motion = motion::methods(ctx);
    let partition = &ctx.eq.partition;
    let gibbs_appell = gibbs_appell::methods(ctx, partition);
    let linearization = ctx.eq.jacobians.then(|| jacobian::methods(ctx, partition));
    let evaluation = [dynamics::methods(ctx), frames::methods(ctx)];
    let gaps = impact::methods(ctx);
    let friction = friction::methods(ctx);
    let methods = quote! {
        #(#values)*
        #motion
        #gibbs_appell
        #linearization
        #(#evaluation)*
        #gaps
        #friction
    };
    (methods, detached::functions(ctx, &detached))
}

/// `M`, `F`, `φ` and the constraints at velocity level, as written or
/// derived.
fn model_values(ctx: &Context) -> Vec<detached::Detached> {
    let (eq, sys) = (ctx.eq, &ctx.eq.system);
    let mass = matrix_function(
        ctx,
        quote!(mass_matrix),
        " The mass matrix `M(q, t)` (symmetric positive definite).",
        Inputs::Positions,
        &sys.mass,
        ctx.n,
    );
    // Bodies' `F` is recursive Newton–Euler's bias (and the inputs), whose
    // adjacent entries are different bodies' forces: as `inverse_dynamics`,
    // returned apart where it is large (`dynamics::strided`).
    let forces = vector_function(
        ctx,
        quote!(forces),
        " The impressed forces `F(q, q̇, t)`.",
        &sys.forces,
        sys.bodies.is_some(),
    );
    let phi: Vec<Id> = sys.constraints.iter().map(|c| c.phi).collect();
    let residual = vector_function(
        ctx,
        quote!(constraint_residual),
        " The constraint residuals `φ(q, q̇, t)`; zero on the constraint manifold.",
        &phi,
        false,
    );
    let velocity_residual = vector_function(
        ctx,
        quote!(constraint_velocity_residual),
        " The constraints at velocity level: `φ̇` for a position-level `φ`, `φ` \
         itself for a velocity-level one; zero on consistent states. Its \
         Jacobian in `q̇` is `A` (used by stabilization and projection).",
        &eq.velocity_constraints,
        false,
    );
    vec![mass, forces, residual, velocity_residual]
}

/// The system's constants: its sizes, the coordinates' names, the
/// constraints' levels, the derivation's text and the sympy export.
fn constants(ctx: &Context, derivation: &str) -> TokenStream {
    let sys = &ctx.eq.system;
    let (n_lit, k_lit) = (Context::dim(ctx.n), Context::dim(ctx.k));
    let nu_lit = Context::dim(sys.inputs);
    let levels = motion::levels(ctx);
    let level = ctx.path(quote!(ConstraintLevel));
    let symbolic_type = ctx.path(quote!(SymbolicSystem));
    let symbolic = symbolic(ctx.eq);
    let names = &sys.coordinate_names;
    quote! {
        /// Number of coordinates `n`.
        pub const DOF: usize = #n_lit;
        /// The coordinates' names, in the order of `q` (for a URDF, the
        /// joints' names as written, in Pinocchio's order).
        pub const COORDINATES: [&'static str; #n_lit] = [#(#names),*];
        /// Number of constraints `k` (rows of `A`, redundant ones included).
        pub const CONSTRAINTS: usize = #k_lit;
        /// Number of control inputs (`inputs: [..]`, the last fields).
        pub const INPUTS: usize = #nu_lit;
        /// For each constraint, whether it was differentiated twice
        /// (position level) or once (velocity level).
        pub const CONSTRAINT_LEVELS: [#level; #k_lit] = [#(#levels),*];
        /// The derivation, as the paper would write it: M, F, φ, A, b, S
        /// and the solution (also in the type's documentation).
        pub const DERIVATION: &'static str = #derivation;
        /// The system in sympy syntax, for independent verification.
        pub const SYMBOLIC: #symbolic_type = #symbolic;
    }
}

/// The struct (a field per parameter and input, the derivation in its
/// documentation), its constructor, and `Default` when it has no fields.
fn struct_definition(
    sys: &crate::model::System,
    n: usize,
    k: usize,
    derivation_doc: &str,
) -> TokenStream {
    let name = &sys.name;
    let vis = &sys.vis;
    let attrs = &sys.attrs;
    let (params, hidden) = struct_fields(sys);
    let plural =
        |count: usize, what: &str| format!("{count} {what}{}", if count == 1 { "" } else { "s" });
    let struct_doc = format!(
        " Generated by `constrained_system!`: {}, {}. \
         See [`{name}::DERIVATION`] for the equations.",
        plural(n, "coordinate"),
        plural(k, "constraint"),
    );
    let fields = field_declarations(sys, &params, &hidden);
    let constructor = constructor(name, &params, &hidden);
    quote! {
        #(#attrs)*
        #[doc = ""]
        #[doc = #struct_doc]
        #[doc = #derivation_doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        // The fields are the user's parameter names, often the literature's
        // (`WFrad`, `Iwr11`): no naming lint on them, here or in `new`.
        #[allow(non_snake_case)]
        #vis struct #name<T = f64> { #fields }

        #constructor
    }
}

/// The struct's public fields (the parameters, then the inputs) and its
/// hidden ones (the friction modes).
fn struct_fields(sys: &crate::model::System) -> (Vec<&Ident>, Vec<&Ident>) {
    let modes = sys.modes();
    let written = sys.parameters.iter().enumerate();
    let params: Vec<&Ident> = written
        .filter(|(i, _)| !modes.contains(i))
        .map(|(_, p)| p)
        .collect();
    let hidden: Vec<&Ident> = sys.parameters[modes].iter().collect();
    (params, hidden)
}

/// The fields with their docs; a marker field where nothing else holds `T`.
fn field_declarations(
    sys: &crate::model::System,
    params: &[&Ident],
    hidden: &[&Ident],
) -> TokenStream {
    let param_docs = params.iter().enumerate().map(|(i, p)| {
        if i < params.len() - sys.inputs {
            format!(" Parameter `{p}`.")
        } else {
            format!(
                " Control input `{p}` (in `forces` only): set it between steps; \
                 the integrators hold it over a step (zero-order hold)."
            )
        }
    });
    // Without a parameter, nothing holds `T`: a marker field does.
    let marker = params.is_empty().then(|| {
        quote! {
            #[doc(hidden)]
            pub __scalar: ::core::marker::PhantomData<T>,
        }
    });
    quote! {
        #( #[doc = #param_docs] pub #params: T, )*
        #(
            /// A friction entry's mode as its sense `s`: `0` sticking, `±1`
            /// slipping (set through `with_friction_modes`).
            #[doc(hidden)]
            pub #hidden: T,
        )*
        #marker
    }
}

/// `new`, from the parameters then the inputs, and `Default` for a struct
/// without them.
fn constructor(name: &Ident, params: &[&Ident], hidden: &[&Ident]) -> TokenStream {
    let marker_value = params
        .is_empty()
        .then(|| quote! { __scalar: ::core::marker::PhantomData });
    let inits = params.iter().map(|p| quote!(#p));
    let inits = inits.chain(hidden.iter().map(|h| quote!(#h: T::zero())));
    let inits: Vec<TokenStream> = inits.chain(marker_value).collect();
    let constructor_body = quote! { Self { #(#inits),* } };
    // The modes start at `Stick`, `T::zero()`: not a `const fn` then.
    let (bound, constness) = if hidden.is_empty() {
        (quote!(), quote!(const))
    } else {
        (
            quote!(: ::constrained::nalgebra::RealField + Copy),
            quote!(),
        )
    };
    let default_impl = params.is_empty().then(|| {
        quote! {
            impl<T #bound> ::core::default::Default for #name<T> {
                fn default() -> Self { Self::new() }
            }
        }
    });
    quote! {
        impl<T #bound> #name<T> {
            /// Creates the system from its parameters, then its control
            /// inputs, in the order declared.
            // One argument per parameter, however many the model has.
            #[allow(non_snake_case, clippy::new_without_default, clippy::too_many_arguments)]
            pub #constness fn new(#(#params: T),*) -> Self { #constructor_body }
        }

        #default_impl
    }
}

/// The longest derivation shown in the type's rustdoc; a longer one is
/// only in `DERIVATION` (the page would not be read, and every build of
/// the docs would carry it).
const DOC_DERIVATION_LIMIT: usize = 64 * 1024;

/// The derivation as a section of the generated type's documentation, so
/// that `cargo doc` shows what the macro derived.
fn derivation_doc(derivation: &str) -> String {
    if derivation.len() > DOC_DERIVATION_LIMIT {
        return format!(
            "\n# Derivation\n\nThe derivation is {} KB long: read `DERIVATION`.",
            derivation.len() / 1024
        );
    }
    // The printer writes no backticks, so the text cannot close the fence.
    format!("\n# Derivation\n\n```text\n{derivation}```")
}

/// A method of the states returning the vector `entries`; with `apart`,
/// returned through `unstride` where it is large ([`dynamics::strided`]).
fn vector_function(
    ctx: &Context,
    name: TokenStream,
    doc: &str,
    entries: &[Id],
    apart: bool,
) -> detached::Detached {
    let ret = ctx.vector(entries.len());
    let v = detached::Value {
        name,
        doc,
        inputs: Inputs::States,
        ret,
        roots: entries,
    };
    let apart = apart && detached::large(ctx, entries);
    detached::value(ctx, &v, |body| {
        if apart {
            dynamics::strided(ctx, body, entries)
        } else {
            ctx.vector_value(entries.iter().map(|&e| body.expr(e)))
        }
    })
}

fn matrix_function(
    ctx: &Context,
    name: TokenStream,
    doc: &str,
    inputs: Inputs,
    rows: &[Vec<Id>],
    cols: usize,
) -> detached::Detached {
    let roots: Vec<Id> = rows.iter().flatten().copied().collect();
    let ret = ctx.matrix(rows.len(), cols);
    let v = detached::Value {
        name,
        doc,
        inputs,
        ret,
        roots: &roots,
    };
    // A large matrix is stored as its entries become known; a small one,
    // whose few values the registers hold anyway, is one literal.
    if !detached::large(ctx, &roots) {
        return detached::value(ctx, &v, |body| {
            ctx.matrix_value(rows.len(), column_major(body, rows, cols))
        });
    }
    let (stores, value) = stored(ctx, rows);
    let body = Body::storing(ctx.eq, stores);
    detached::value_of(ctx, &v, body, |_| value)
}

/// The matrix `rows` (row by row) as outputs a body stores as soon as it
/// knows each entry ([`Body::storing`]): into the local `__out0`, zeros
/// where nothing is written, with that local as the value.
fn stored(ctx: &Context, rows: &[Vec<Id>]) -> (Stores, TokenStream) {
    let g = &ctx.eq.system.graph;
    let local = Context::local("out", 0);
    let cols = rows.first().map_or(0, Vec::len);
    let mut places = Vec::new();
    for j in 0..cols {
        for (i, row) in rows.iter().enumerate() {
            if !g.is_zero(row[j]) {
                let (r, c) = (Context::dim(i), Context::dim(j));
                places.push((quote!(#local.data.0[#c][#r]), row[j]));
            }
        }
    }
    // The entries built last first: the composite-rigid-body pass builds
    // the columns of the bodies nearest the root first, whose composite
    // inertias need every other one, so in that order every composite
    // would be held before any entry is stored. Farthest out first, each
    // body's composite comes right before its column, as in Featherstone's
    // loop from the leaves.
    places.sort_by_key(|&(_, id)| std::cmp::Reverse(id));
    let zeros = ctx.matrix_zeros(rows.len(), cols);
    let stores = Stores {
        local: quote! { let mut #local = #zeros; },
        places,
    };
    (stores, quote!(#local))
}

/// The entries column by column: nalgebra stores columns.
fn column_major(body: &Body, rows: &[Vec<Id>], cols: usize) -> Vec<Vec<TokenStream>> {
    (0..cols)
        .map(|j| rows.iter().map(|row| body.expr(row[j])).collect())
        .collect()
}

fn constraint_matrices(ctx: &Context) -> detached::Detached {
    let eq = ctx.eq;
    let (n, k) = (ctx.n, ctx.k);
    let mut roots: Vec<Id> = eq.a.iter().flatten().copied().collect();
    roots.extend(&eq.b);
    let (a_type, b_type) = (ctx.matrix(k, n), ctx.vector(k));
    let v = detached::Value {
        name: quote!(constraint_matrices),
        doc: " The constraint equations `A q̈ = b` as `(A, b)`: the constraints\n \
              differentiated once (velocity level) or twice (position level).",
        inputs: Inputs::States,
        ret: quote!((#a_type, #b_type)),
        roots: &roots,
    };
    detached::value(ctx, &v, |body| {
        let a = ctx.matrix_value(k, column_major(body, &eq.a, n));
        let b = ctx.vector_value(eq.b.iter().map(|&e| body.expr(e)));
        quote!((#a, #b))
    })
}

/// The length of the emitted `SYMBOLIC` value as Rust tokens (its strings
/// and their structure): what the macro writes for sympy, for measuring
/// how it grows (`examples/derivation_size.rs`).
pub fn symbolic_text_len(eq: &Equations) -> usize {
    symbolic(eq).to_string().len()
}

/// The `SymbolicSystem` constant.
fn symbolic(eq: &Equations) -> TokenStream {
    let sys = &eq.system;
    let coordinates: Vec<String> = sys.coordinates.iter().map(ToString::to_string).collect();
    let parameters: Vec<String> = sys.parameters.iter().map(ToString::to_string).collect();
    let (parameters_only, inputs) = parameters.split_at(parameters.len() - sys.inputs);
    // Shared subexpressions are named (`__s1`, …) and listed in
    // `definitions`, so that the text grows with the DAG.
    let mut roots: Vec<Id> = sys.mass.iter().flatten().copied().collect();
    roots.extend(&sys.forces);
    roots.extend(sys.constraints.iter().map(|c| c.phi));
    roots.extend(eq.a.iter().flatten());
    roots.extend(&eq.b);
    if let Some(e) = &sys.energies {
        roots.extend(e.kinetic.iter().chain(&e.potential).chain(&e.applied));
    }
    let shared = shared_subexpressions(&sys.graph, &roots, &HashMap::new(), |i| format!("__s{i}"));
    let names: HashMap<Id, String> = shared.iter().map(|(id, n)| (*id, n.clone())).collect();
    let p = Printer::new(&sys.graph, &coordinates, &parameters, Style::Sympy).with_names(&names);
    let definitions = shared.iter().map(|(id, name)| {
        let value = p.print_expanded(*id);
        quote!((#name, #value))
    });
    let vector = |ids: &[Id]| {
        let texts = ids.iter().map(|&i| p.print(i));
        quote! { &[#(#texts),*] }
    };
    let matrix = |rows: &[Vec<Id>]| {
        let rows = rows.iter().map(|r| vector(r));
        quote! { &[#(#rows),*] }
    };
    let name = sys.name.to_string();
    let mass = matrix(&sys.mass);
    let forces = vector(&sys.forces);
    let phi: Vec<Id> = sys.constraints.iter().map(|c| c.phi).collect();
    let constraints = vector(&phi);
    let a = matrix(&eq.a);
    let b = vector(&eq.b);
    let energies = sympy_energies(&p, sys.energies.as_ref());
    quote! {
        ::constrained::SymbolicSystem {
            name: #name,
            coordinates: &[#(#coordinates),*],
            parameters: &[#(#parameters_only),*],
            inputs: &[#(#inputs),*],
            mass: #mass,
            forces: #forces,
            constraints: #constraints,
            a_matrix: #a,
            b_vector: #b,
            energies: #energies,
            definitions: &[#(#definitions),*],
        }
    }
}

/// The `SymbolicEnergies` of a system given by energies, else `None`.
fn sympy_energies(p: &Printer, energies: Option<&crate::model::Energies>) -> TokenStream {
    let Some(e) = energies else {
        return quote!(::core::option::Option::None);
    };
    let kinetic = match e.kinetic {
        Some(t) => {
            let t = p.print(t);
            quote!(::core::option::Option::Some(#t))
        }
        None => quote!(::core::option::Option::None),
    };
    let potential = e.potential.map_or_else(|| "0".to_string(), |v| p.print(v));
    let applied = e.applied.iter().map(|&i| p.print(i));
    quote! {
        ::core::option::Option::Some(::constrained::SymbolicEnergies {
            kinetic: #kinetic,
            potential: #potential,
            generalized_forces: &[#(#applied),*],
        })
    }
}
