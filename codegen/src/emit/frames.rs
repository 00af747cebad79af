//! The kinematics methods of a system with a `frames` section: per named
//! frame `f`, `f_placement`, `f_jacobian`, `f_velocity` and
//! `f_acceleration_bias`, and `center_of_mass`, `center_of_mass_jacobian`,
//! `center_of_mass_and_jacobian`, `center_of_mass_velocity`,
//! `centroidal_map` and `centroidal_map_bias`
//! (the expressions of
//! `crate::bodies::kinematics`). One method per frame and quantity, each
//! its own straight-line body, so that a binary compiles only those it
//! calls. A new one is also a row of the test's `METHODS` and of the table
//! in `docs/generated.md`.
//!
//! They are plain values, not `Result`s: they divide by nothing that can
//! vanish but the total mass, and they take no square root.

use super::body::Body;
use super::context::{Context, Inputs};
use crate::bodies::kinematics::{CenterOfMass, Frame};
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The shape a method returns.
#[derive(Clone, Copy)]
enum Shape {
    /// `(SMatrix<T, 3, 3>, SVector<T, 3>)` from 12 entries, `R` row by row
    /// then `p`.
    Placement,
    /// `SVector<T, len>`.
    Vector,
    /// `SMatrix<T, rows, n>`, row by row.
    Matrix,
    /// `(SVector<T, 3>, SMatrix<T, 3, n>)`: a point, then its Jacobian row
    /// by row.
    PointAndJacobian,
}

/// The kinematics methods the system has: none without a `frames` section.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let Some(k) = ctx
        .eq
        .system
        .bodies
        .as_ref()
        .and_then(|b| b.kinematics.as_ref())
    else {
        return TokenStream::new();
    };
    let mut out: TokenStream = k.frames.iter().map(|f| frame(ctx, f)).collect();
    if let Some(c) = &k.center_of_mass {
        out.extend(center_of_mass(ctx, c));
    }
    out
}

fn frame(ctx: &Context, f: &Frame) -> TokenStream {
    let name = &f.name;
    let mut placement: Vec<Id> = f.rotation.iter().flatten().copied().collect();
    placement.extend(f.position);
    let doc = format!(
        " The placement of frame `{name}` in the world, `(R, p)`: its axes as \
         the columns of `R` and its origin `p`, in world coordinates (Pinocchio's \
         `data.oMf[frame]`, `R = rotation()`, `p = translation()`)."
    );
    let jacobian = format!(
        " The Jacobian of frame `{name}`, 6 × n: `J q̇ = [v; ω]`, the velocity of \
         its origin and its angular velocity, both in world axes (Pinocchio's \
         `getFrameJacobian(.., LOCAL_WORLD_ALIGNED)`, rows [linear; angular]). \
         `LOCAL`: premultiply each 3-row block by `Rᵀ`; `WORLD`: add `[p]ₓ` times \
         the angular block to the linear one (`v₀ = v − ω × p`). Columns of a \
         quaternion joint are by the quaternion's rates `q̇`."
    );
    let velocity = format!(
        " The velocity of frame `{name}`, `J q̇ = [v; ω]` in world axes \
         (Pinocchio's `getFrameVelocity(.., LOCAL_WORLD_ALIGNED)`)."
    );
    let bias = format!(
        " The acceleration bias of frame `{name}`, `J̇ q̇ = [p̈; ω̇]` at `q̈ = 0` in \
         world axes: its classical acceleration is `J q̈ + J̇ q̇` (Pinocchio's \
         `getFrameClassicalAcceleration(.., LOCAL_WORLD_ALIGNED)` at `q̈ = 0`)."
    );
    [
        (
            "placement",
            doc,
            Inputs::Positions,
            vec![placement],
            Shape::Placement,
        ),
        (
            "jacobian",
            jacobian,
            Inputs::Positions,
            f.jacobian.clone(),
            Shape::Matrix,
        ),
        (
            "velocity",
            velocity,
            Inputs::States,
            vec![f.velocity.clone()],
            Shape::Vector,
        ),
        (
            "acceleration_bias",
            bias,
            Inputs::States,
            vec![f.bias.clone()],
            Shape::Vector,
        ),
    ]
    .into_iter()
    .map(|(what, doc, inputs, rows, shape)| {
        let method = format_ident!("{}_{}", name, what);
        emit(ctx, quote!(#method), &doc, inputs, &rows, shape)
    })
    .collect()
}

fn center_of_mass(ctx: &Context, c: &CenterOfMass) -> TokenStream {
    let mut out = emit(
        ctx,
        quote!(center_of_mass),
        " The centre of mass of every body, in world coordinates (Pinocchio's \
         `centerOfMass`).",
        Inputs::Positions,
        &[c.position.to_vec()],
        Shape::Vector,
    );
    out.extend(emit(
        ctx,
        quote!(center_of_mass_jacobian),
        " The Jacobian of the centre of mass, 3 × n: its velocity is `J q̇` \
         (Pinocchio's `jacobianCenterOfMass`). Columns of a quaternion joint \
         are by the quaternion's rates `q̇`.",
        Inputs::Positions,
        &c.jacobian,
        Shape::Matrix,
    ));
    let mut both = vec![c.position.to_vec()];
    both.extend(c.jacobian.iter().cloned());
    out.extend(emit(
        ctx,
        quote!(center_of_mass_and_jacobian),
        " The centre of mass and its Jacobian together, `(c, ∂c/∂q)`, sharing the \
         subtrees' first moments (Pinocchio's `jacobianCenterOfMass`, which fills \
         `data.com[0]` and returns `Jcom`).",
        Inputs::Positions,
        &both,
        Shape::PointAndJacobian,
    ));
    out.extend(emit(
        ctx,
        quote!(center_of_mass_velocity),
        " The velocity of the centre of mass, `ċ = J q̇` in world axes (Pinocchio's \
         `data.vcom[0]`).",
        Inputs::States,
        &[c.velocity.to_vec()],
        Shape::Vector,
    ));
    out.extend(centroidal(ctx, c));
    out
}

/// `centroidal_map` and `centroidal_map_bias`.
fn centroidal(ctx: &Context, c: &CenterOfMass) -> TokenStream {
    let mut out = emit(
        ctx,
        quote!(centroidal_map),
        " The centroidal momentum matrix `A_G`, 6 × n: the momentum of every body \
         about the centre of mass is `h_G = A_G q̇ = [P; L_G]`, the total linear \
         momentum and the angular momentum about the centre of mass, both in world \
         axes (Pinocchio's `computeCentroidalMap`, rows [linear; angular]). Columns \
         of a quaternion joint are by the quaternion's rates `q̇`, as in every \
         Jacobian here: `A_G` maps this system's `q̇`, not Pinocchio's `v`.",
        Inputs::Positions,
        &c.centroidal_map,
        Shape::Matrix,
    );
    out.extend(emit(
        ctx,
        quote!(centroidal_map_bias),
        " The bias of the centroidal momentum, `Ȧ_G q̇`: its rate is \
         `ḣ_G = A_G q̈ + Ȧ_G q̇` (Pinocchio's `computeCentroidalMapTimeVariation`, \
         `dAg · v`), world axes, rows [linear; angular about the centre of mass].",
        Inputs::States,
        std::slice::from_ref(&c.centroidal_bias),
        Shape::Vector,
    ));
    out
}

/// One method returning `rows` in `shape`.
fn emit(
    ctx: &Context,
    name: TokenStream,
    doc: &str,
    inputs: Inputs,
    rows: &[Vec<Id>],
    shape: Shape,
) -> TokenStream {
    let roots: Vec<Id> = rows.iter().flatten().copied().collect();
    let body = Body::new(ctx.eq, &roots);
    let preamble = body.preamble();
    let entries: Vec<TokenStream> = roots.iter().map(|&e| body.expr(e)).collect();
    let (value, ret) = match shape {
        Shape::Placement => {
            let columns = (0..3).map(|c| (0..3).map(|r| entries[3 * r + c].clone()).collect());
            let rotation = ctx.matrix_value(3, columns.collect());
            let position = ctx.vector_value(entries[9..].iter().cloned());
            let ret = (ctx.matrix(3, 3), ctx.vector(3));
            let (r, p) = ret;
            (quote!((#rotation, #position)), quote!((#r, #p)))
        }
        Shape::Vector => (ctx.vector_value(entries), ctx.vector(roots.len())),
        Shape::Matrix => matrix(ctx, rows, &entries),
        Shape::PointAndJacobian => {
            let point = ctx.vector_value(entries[..3].iter().cloned());
            let (jacobian, matrix_type) = matrix(ctx, &rows[1..], &entries[3..]);
            let vector_type = ctx.vector(3);
            (
                quote!((#point, #jacobian)),
                quote!((#vector_type, #matrix_type)),
            )
        }
    };
    let params = ctx.params(inputs);
    quote! {
        #[doc = #doc]
        #[inline]
        pub fn #name(&self, #params) -> #ret {
            #preamble
            #value
        }
    }
}

/// The value and type of the matrix of `rows`, whose entries are
/// `entries` row by row.
fn matrix(ctx: &Context, rows: &[Vec<Id>], entries: &[TokenStream]) -> (TokenStream, TokenStream) {
    let cols = rows.first().map_or(0, Vec::len);
    let columns = (0..cols)
        .map(|c| {
            (0..rows.len())
                .map(|r| entries[r * cols + c].clone())
                .collect()
        })
        .collect();
    (
        ctx.matrix_value(rows.len(), columns),
        ctx.matrix(rows.len(), cols),
    )
}

#[cfg(test)]
mod tests {
    /// One generated kinematics method: `{frame}` in `name` stands for each
    /// frame's name (`docs/generated.md` has a row for each, checked by a
    /// test).
    struct Method {
        /// The method's name, `{frame}` for the frame's.
        name: &'static str,
        /// Its arguments after `&self`, as `docs/generated.md` writes them.
        args: &'static str,
    }

    /// The kinematics methods, in the order they are emitted.
    const METHODS: &[Method] = &[
        Method {
            name: "{frame}_placement",
            args: "q, t",
        },
        Method {
            name: "{frame}_jacobian",
            args: "q, t",
        },
        Method {
            name: "{frame}_velocity",
            args: "q, qd, t",
        },
        Method {
            name: "{frame}_acceleration_bias",
            args: "q, qd, t",
        },
        Method {
            name: "center_of_mass",
            args: "q, t",
        },
        Method {
            name: "center_of_mass_jacobian",
            args: "q, t",
        },
        Method {
            name: "center_of_mass_and_jacobian",
            args: "q, t",
        },
        Method {
            name: "center_of_mass_velocity",
            args: "q, qd, t",
        },
        Method {
            name: "centroidal_map",
            args: "q, t",
        },
        Method {
            name: "centroidal_map_bias",
            args: "q, qd, t",
        },
    ];

    /// Every kinematics method has a row of the table of generated items
    /// in `docs/generated.md`, with its arguments as generated.
    #[test]
    fn docs_table_lists_every_kinematics_method() {
        let docs = include_str!("../../../docs/generated.md");
        let rows: Vec<&str> = docs.lines().filter(|l| l.starts_with("| `")).collect();
        for m in METHODS {
            let item = format!("`{}({})`", m.name, m.args);
            assert!(
                rows.iter().any(|r| r.contains(&item)),
                "docs/generated.md has no row for {item}"
            );
        }
    }
}
