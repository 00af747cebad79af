//! The `bodies` and `gravity` sections: each body's fields checked and
//! lowered into a [`Described`] body of `crate::bodies`. The joints'
//! coordinates become the system's coordinates (read first, by
//! [`joint_coordinates`], so that every other section can name them).
//!
//! ```text
//! bodies: [
//!     upper {                              // the body's name
//!         parent: world,                   // optional: `world` or an earlier body
//!         joint: revolute(q1, [0, 0, 1]),  // revolute | prismatic (coordinate, axis) | fixed
//!                                          // | helical(q, axis, pitch) | planar(x, y, θ)
//!                                          // | spherical(qw, qx, qy, qz)
//!                                          // | free(x, y, z, qw, qx, qy, qz) (`super::free`)
//!         xyz: [0, 0, 0.333],              // optional: the joint frame's origin in the parent's
//!         rpy: [0, 0, 0],                  // optional: its orientation, R = Rz(yaw) Ry(pitch) Rx(roll)
//!         mass: m1,                        // optional: 0
//!         com: [0, 0, -0.1],               // optional: the centre of mass, in the body's frame
//!         inertia: diag[0.1, 0.1, 0.02],   // optional: about the centre of mass (or [[..], [..], [..]])
//!     },
//! ]
//! ```

use super::ctxt::Errors;
use super::lower::Lowerer;
use crate::bodies::spatial::{self, Inertia, V3};
use crate::bodies::{Described, Joint, JointKind, Placement};
use crate::expr::{Id, Sym};
use crate::parse::{BodyInput, List, MassInput};
use syn::{Expr, Ident};

/// The fields a body may have, for messages.
const FIELDS: &str = "`parent`, `joint`, `xyz`, `rpy`, `mass`, `com`, `inertia`";

/// The coordinates named by the bodies' joints, in order.
pub fn joint_coordinates(bodies: &List<BodyInput>) -> Vec<Ident> {
    bodies
        .items
        .iter()
        .flat_map(
            |b| match (super::free::quaternion_call(b), field(b, "joint")) {
                (Some((call, _)), _) => super::free::names(call),
                (None, Some(Expr::Call(call))) if is_call(call, "planar") => {
                    call.args.iter().filter_map(single_ident).cloned().collect()
                }
                (None, Some(Expr::Call(call))) => call
                    .args
                    .first()
                    .and_then(single_ident)
                    .cloned()
                    .into_iter()
                    .collect(),
                _ => Vec::new(),
            },
        )
        .collect()
}

/// The joints a body may have, as written, for messages: one row of the
/// joint model (`crate::bodies::joint`) each, and `fixed`.
const JOINTS: &str = "`revolute(q, axis)` (or `continuous`), `prismatic(q, axis)`, \
                      `helical(q, axis, pitch)`, `planar(x, y, θ)`, `fixed`, \
                      `spherical(qw, qx, qy, qz)` or `free(x, y, z, qw, qx, qy, qz)`, \
                      with `axis` `[x, y, z]`";

fn is_call(call: &syn::ExprCall, name: &str) -> bool {
    single_ident(&call.func).is_some_and(|f| f == name)
}

/// The `planar(x, y, θ)` call of a body's joint, if it is one.
fn planar_call(body: &BodyInput) -> Option<&syn::ExprCall> {
    match field(body, "joint")? {
        Expr::Call(call) if is_call(call, "planar") => Some(call),
        _ => None,
    }
}

fn field<'a>(body: &'a BodyInput, name: &str) -> Option<&'a Expr> {
    body.fields.iter().find(|(k, _)| k == name).map(|(_, e)| e)
}

pub(super) fn single_ident(e: &Expr) -> Option<&Ident> {
    match e {
        Expr::Path(p) if p.qself.is_none() && p.attrs.is_empty() => p.path.get_ident(),
        _ => None,
    }
}

impl Lowerer<'_> {
    /// Lowers every body; `coordinates` are the joints', in order.
    pub fn bodies(&mut self, list: &List<BodyInput>, coordinates: &[Ident]) -> Vec<Described> {
        if list.items.is_empty() {
            self.errors
                .at(list.span, "`bodies` must list at least one body");
        }
        let mut described: Vec<Described> = Vec::new();
        let mut names: Vec<String> = Vec::new();
        for body in &list.items {
            let name = body.name.to_string();
            if name == "world" || names.contains(&name) {
                let why = if name == "world" {
                    "`world` is the fixed frame"
                } else {
                    "declared twice"
                };
                self.errors
                    .spanned(&body.name, format!("body `{name}`: {why}"));
            }
            check_fields(self.errors, body);
            let parent = self.parent(body, &names);
            if let Some(call) = super::free::quaternion_call(body) {
                let placement = self.placement(body);
                let inertia = self.inertia(body);
                let at = (parent, placement, described.len());
                let parts = self.quaternion_bodies(call, coordinates, &name, at, inertia);
                names.extend(parts.iter().map(|d| d.name.clone()));
                described.extend(parts);
                continue;
            }
            if let Some(call) = planar_call(body) {
                let placement = self.placement(body);
                let inertia = self.inertia(body);
                let at = (parent, placement, described.len());
                let parts = self.planar_bodies(call, coordinates, &name, at, inertia);
                names.extend(parts.iter().map(|d| d.name.clone()));
                described.extend(parts);
                continue;
            }
            let joint = self.joint(body, coordinates);
            let placement = self.placement(body);
            let inertia = self.inertia(body);
            names.push(name.clone());
            described.push(Described {
                name,
                parent,
                placement,
                joint,
                inertia,
            });
        }
        described
    }

    /// `gravity: [gx, gy, gz]`, constant or parametric; default `[0, 0, −9.81]`.
    pub fn gravity(&mut self, list: Option<&List<Expr>>) -> V3 {
        match list {
            Some(list) => {
                let v = self.vector(list, "`gravity`", 3);
                for (e, &id) in list.items.iter().zip(&v) {
                    self.constant_of_state(e, id, "`gravity`");
                }
                [v[0], v[1], v[2]]
            }
            None => {
                let z = self.graph.int(0);
                let g = self.graph.num(crate::expr::num::Num::Rational(-981, 100));
                [z, z, g]
            }
        }
    }

    fn parent(&mut self, body: &BodyInput, earlier: &[String]) -> Option<usize> {
        let e = field(body, "parent")?;
        match single_ident(e) {
            Some(p) if p == "world" => None,
            Some(p) => {
                let found = earlier.iter().position(|n| p == n);
                if found.is_none() {
                    self.errors.spanned(
                        p,
                        format!(
                            "unknown parent `{p}`: expected `world` or a body declared before `{}`",
                            body.name
                        ),
                    );
                }
                found
            }
            None => {
                self.errors
                    .spanned(e, "`parent` takes a body's name or `world`");
                None
            }
        }
    }

    /// `planar(x, y, θ)`: the body and the two massless slides under it
    /// (`crate::bodies::joint::planar`); nothing, with an error, unless it
    /// names three coordinates.
    fn planar_bodies(
        &mut self,
        call: &syn::ExprCall,
        coordinates: &[Ident],
        name: &str,
        at: (Option<usize>, Placement, usize),
        inertia: Inertia,
    ) -> Vec<Described> {
        let index: Option<Vec<usize>> = call
            .args
            .iter()
            .map(|a| single_ident(a).and_then(|q| coordinates.iter().position(|c| c == q)))
            .collect();
        let Some(index) = index.filter(|i| i.len() == 3) else {
            self.errors.spanned(
                call,
                "expected `planar(x, y, θ)`: the body's origin in its joint frame's \
                 x–y plane and its turn about that frame's z axis, three coordinates",
            );
            return Vec::new();
        };
        let mut parts = crate::bodies::joint::planar(self.graph, name, at, index[0], inertia);
        // Each slide and the turn keep the coordinate the call names.
        for (part, &c) in parts.iter_mut().zip(&index) {
            if let Some(j) = part.joint.as_mut() {
                j.coordinate = c;
            }
        }
        parts
    }

    fn joint(&mut self, body: &BodyInput, coordinates: &[Ident]) -> Option<Joint> {
        let Some(e) = field(body, "joint") else {
            self.errors.at(
                body.span,
                format!("body `{}` has no `joint` ({JOINTS})", body.name),
            );
            return None;
        };
        let usage = format!("expected {JOINTS}");
        if single_ident(e).is_some_and(|k| k == "fixed") {
            return None;
        }
        let Expr::Call(call) = e else {
            self.errors.spanned(e, usage);
            return None;
        };
        let args: Vec<&Expr> = call.args.iter().collect();
        let kind = match (
            single_ident(&call.func).map(ToString::to_string).as_deref(),
            args.len(),
        ) {
            (Some("revolute" | "continuous"), 2) => JointKind::Revolute,
            (Some("prismatic"), 2) => JointKind::Prismatic,
            (Some("helical"), 3) => {
                let pitch = self.lower(args[2]);
                self.constant_of_state(args[2], pitch, "the pitch");
                JointKind::Helical { pitch }
            }
            _ => {
                self.errors.spanned(e, usage);
                return None;
            }
        };
        let (Some(q), Some(axis)) = (args.first().and_then(|a| single_ident(a)), args.get(1))
        else {
            self.errors.spanned(e, usage);
            return None;
        };
        let coordinate = coordinates.iter().position(|c| c == q)?;
        let axis = self.axis(axis)?;
        Some(Joint::new(kind, coordinate, axis))
    }

    /// A joint's axis, normalised (exactly, where it is a constant).
    fn axis(&mut self, e: &Expr) -> Option<V3> {
        let v = self.triple(e, "the axis")?;
        let norm2 = spatial::dot(self.graph, v, v);
        if self.graph.is_zero(norm2) {
            self.errors.spanned(e, "the joint's axis is zero");
            return None;
        }
        let norm = self.graph.sqrt(norm2);
        Some(v.map(|c| self.graph.div(c, norm)))
    }

    /// `[x, y, z]` of constants or parameters.
    pub(super) fn triple(&mut self, e: &Expr, what: &str) -> Option<V3> {
        let Expr::Array(array) = e else {
            self.errors.spanned(e, format!("{what} is `[x, y, z]`"));
            return None;
        };
        if array.elems.len() != 3 {
            self.errors.spanned(
                e,
                format!("{what} has 3 entries, not {}", array.elems.len()),
            );
            return None;
        }
        let ids: Vec<Id> = array
            .elems
            .iter()
            .map(|x| {
                let id = self.lower(x);
                self.constant_of_state(x, id, what);
                id
            })
            .collect();
        Some([ids[0], ids[1], ids[2]])
    }

    fn optional_triple(&mut self, body: &BodyInput, key: &str) -> V3 {
        let zero = spatial::zero(self.graph);
        field(body, key)
            .and_then(|e| self.triple(e, &format!("`{key}`")))
            .unwrap_or(zero)
    }

    pub(super) fn placement(&mut self, body: &BodyInput) -> Placement {
        let translation = self.optional_triple(body, "xyz");
        let angles = self.optional_triple(body, "rpy");
        Placement {
            rotation: spatial::rpy(self.graph, angles),
            translation,
        }
    }

    fn inertia(&mut self, body: &BodyInput) -> Inertia {
        let mass = match field(body, "mass") {
            Some(e) => {
                let id = self.lower(e);
                self.constant_of_state(e, id, "`mass`");
                id
            }
            None => self.graph.int(0),
        };
        let com = self.optional_triple(body, "com");
        let zero = self.graph.int(0);
        let mut about_com = [[zero; 3]; 3];
        if let Some((_, input)) = &body.inertia {
            self.inertia_tensor(input, &mut about_com);
        }
        Inertia::from_com(self.graph, mass, com, &about_com)
    }

    fn inertia_tensor(&mut self, input: &MassInput, out: &mut [[Id; 3]; 3]) {
        match input {
            MassInput::Diagonal(list) => {
                super::check::length(self.errors, list.span, "`inertia`", list.items.len(), 3);
                for (i, e) in list.items.iter().enumerate().take(3) {
                    out[i][i] = self.lower(e);
                    self.constant_of_state(e, out[i][i], "`inertia`");
                }
            }
            MassInput::Full(rows) => {
                super::check::length(self.errors, rows.span, "`inertia`", rows.items.len(), 3);
                for (i, row) in rows.items.iter().enumerate().take(3) {
                    let what = format!("row {} of `inertia`", i + 1);
                    super::check::length(self.errors, row.span, &what, row.items.len(), 3);
                    for (j, e) in row.items.iter().enumerate().take(3) {
                        out[i][j] = self.lower(e);
                        self.constant_of_state(e, out[i][j], "`inertia`");
                    }
                }
                let asymmetric = [(1, 0), (2, 0), (2, 1)]
                    .into_iter()
                    .filter(|&(i, j)| out[i][j] != out[j][i]);
                for (i, j) in asymmetric.collect::<Vec<_>>() {
                    let row = &rows.items[i.min(rows.items.len() - 1)];
                    self.errors.at(
                        row.span,
                        format!(
                            "`inertia` is not symmetric: entries ({}, {}) and ({}, {}) differ",
                            i + 1,
                            j + 1,
                            j + 1,
                            i + 1
                        ),
                    );
                }
            }
        }
    }

    /// A body's geometry and inertia are fixed in the body: constants or
    /// parameters, never the state or time.
    fn constant_of_state(&mut self, e: &Expr, id: Id, what: &str) {
        let moving = self
            .graph
            .mentions(id, |s| matches!(s, Sym::Coord(_) | Sym::Vel(_) | Sym::Time));
        if moving {
            self.errors.spanned(
                e,
                format!("{what} of a body may use numbers and parameters, not coordinates, velocities or `t`"),
            );
        }
    }
}

fn check_fields(errors: &mut Errors, body: &BodyInput) {
    let known = ["parent", "joint", "xyz", "rpy", "mass", "com"];
    let mut seen: Vec<String> = Vec::new();
    for (key, _) in &body.fields {
        let k = key.to_string();
        if !known.contains(&k.as_str()) {
            errors.spanned(
                key,
                format!("unknown field `{k}` of a body: expected one of {FIELDS}"),
            );
        } else if seen.contains(&k) {
            errors.spanned(key, format!("duplicate field `{k}`"));
        }
        seen.push(k);
    }
}
