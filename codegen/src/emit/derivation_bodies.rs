//! The derivation's part per body, for systems with bodies: each movable
//! body's joint, placement and inertia, and the intermediates of the
//! recursions that give `M` and the bias forces, in Featherstone's
//! notation (*Rigid Body Dynamics Algorithms*, ch. 5–6). Each intermediate
//! that is a sum of several terms is named (`v₂.ωx`, `f₃.nz`, `Iᶜ₁.m`)
//! and written out once; `M` and `F` below read in those names, so that a
//! robot's derivation reviews as a diff and grows linearly with its
//! bodies.

use crate::bodies::spatial::{Spatial, M3, V3};
use crate::bodies::{Body, Trace};
use crate::expr::num::Num;
use crate::expr::print::{subscript, Printer};
use crate::expr::{Func, Graph, Id, Node};
use crate::model::BodyTerms;
use std::collections::HashMap;
use std::fmt::Write;

const AXES: [&str; 3] = ["x", "y", "z"];

/// How an intermediate is named.
enum Naming {
    /// A number, a variable or a short product (`−q̇1·sin(q2)`): written out.
    Inline,
    /// A sum, or a product with a sum among its factors: named.
    Named,
    /// `−s` for a sum `s`, which is what other expressions contain (the
    /// negation is folded into them): both named, `s` as `(−name)`.
    Negated(Id),
}

fn naming(g: &Graph, id: Id) -> Naming {
    let sum = |id: Id| match g.node(id) {
        Node::Func(Func::Hold, _) => true,
        Node::Add(terms, c0) => terms.len() + usize::from(!c0.is_zero()) >= 2,
        _ => false,
    };
    match g.node(id) {
        _ if sum(id) => Naming::Named,
        Node::Mul(factors) if factors.iter().any(|&(f, _)| sum(f)) => Naming::Named,
        Node::Add(terms, c0) if c0.is_zero() && terms.len() == 1 => {
            let (s, c) = terms[0];
            if c == Num::MINUS_ONE && sum(s) {
                Naming::Negated(s)
            } else {
                Naming::Inline
            }
        }
        _ => Naming::Inline,
    }
}

/// Names each body's intermediates that are sums or multiples of one
/// (written out, they would repeat wherever they occur); first name first.
pub fn name_intermediates(g: &Graph, bodies: &BodyTerms, names: &mut HashMap<Id, String>) {
    for (i, t) in bodies.trace.iter().enumerate() {
        for (id, name) in labelled(i, t) {
            match naming(g, id) {
                Naming::Inline => {}
                Naming::Named => {
                    names.entry(id).or_insert(name);
                }
                Naming::Negated(s) => {
                    names.entry(s).or_insert(format!("(−{name})"));
                    names.entry(id).or_insert(name);
                }
            }
        }
    }
}

/// The definition of a named intermediate.
fn definition(g: &Graph, p: &Printer, id: Id) -> String {
    match naming(g, id) {
        Naming::Negated(s) => {
            let e = p.print_expanded(s);
            if e.starts_with('(') && e.ends_with(')') {
                format!("−{e}")
            } else {
                format!("−({e})")
            }
        }
        _ => p.print_expanded(id),
    }
}

/// Every intermediate of every body, for the shared-subexpression roots.
pub fn roots(bodies: &BodyTerms) -> Vec<Id> {
    let labelled = bodies
        .trace
        .iter()
        .enumerate()
        .flat_map(|(i, t)| labelled(i, t));
    labelled.map(|(id, _)| id).collect()
}

/// The six components of a spatial vector, labelled `{sym}ᵢ.{part}{axis}`.
fn spatial_labels(sym: &str, i: usize, v: &Spatial, parts: [&str; 2]) -> Vec<(Id, String)> {
    let s = subscript(i + 1);
    let mut out = Vec::with_capacity(6);
    for (part, vector) in parts.iter().zip([v.angular, v.linear]) {
        for (axis, id) in AXES.iter().zip(vector) {
            out.push((id, format!("{sym}{s}.{part}{axis}")));
        }
    }
    out
}

/// Body `i`'s intermediates with their names, in the order printed.
fn labelled(i: usize, t: &Trace) -> Vec<(Id, String)> {
    let s = subscript(i + 1);
    let mut out = spatial_labels("v", i, &t.velocity, ["ω", "v"]);
    out.extend(spatial_labels("a", i, &t.acceleration, ["ω̇", "v̇"]));
    if let Some(center) = &t.center {
        for (sym, vector) in [
            ("ċ", center.velocity),
            ("c̈", center.acceleration),
            ("L", center.spin),
        ] {
            for (axis, &id) in AXES.iter().zip(&vector) {
                out.push((id, format!("{sym}{s}.{axis}")));
            }
        }
    }
    out.extend(spatial_labels("f", i, &t.force, ["n", "f"]));
    let c = &t.composite;
    out.push((c.mass, format!("Iᶜ{s}.m")));
    for (axis, &id) in AXES.iter().zip(&c.first_moment) {
        out.push((id, format!("Iᶜ{s}.h{axis}")));
    }
    for (r, row) in c.rotational.iter().enumerate() {
        for (k, &id) in row.iter().enumerate().skip(r) {
            out.push((id, format!("Iᶜ{s}.I{}{}", AXES[r], AXES[k])));
        }
    }
    out
}

/// How `M` is formed: carried through the joints in the bodies' own axes,
/// or in world axes where that costs fewer operations
/// (`crate::bodies::world_mass`), for `M` and for its velocity form.
fn mass_statement((plain, velocity): (bool, bool)) -> String {
    const THROUGH: &str = "Mᵢᵢ = Sᵢᵀ Iᶜᵢ Sᵢ,  Mⱼᵢ = Sⱼᵀ jX_iᵀ … Iᶜᵢ Sᵢ for each ancestor j of i";
    const WORLD: &str = "each body's frame oXᵢ = oX_λ λXᵢ, its columns Sᵢʷ = oXᵢ Sᵢ, \
         composites Iᶜᵢʷ = oXᵢ⁻ᵀ Iᵢ oXᵢ⁻¹ + Σ_children Iᶜⱼʷ (not the Iᶜᵢ below),  \
         Mⱼᵢ = Sⱼʷᵀ Iᶜᵢʷ Sᵢʷ for j = i and each ancestor j of i";
    const WHERE: &str =
        "M in world axes, where frames placed by dense rotations make that the cheaper";
    match (plain, velocity) {
        (false, false) => format!("{THROUGH}."),
        (true, true) => format!("{WHERE} (its velocity form too): {WORLD}."),
        (true, false) => format!("{WHERE} (its velocity form in the bodies' own axes): {WORLD}."),
        (false, true) => format!(
            "{THROUGH}; its velocity form in world axes, where that is the cheaper: {WORLD}."
        ),
    }
}

/// The part per body, before `M` and `F`.
pub fn text(
    w: &mut String,
    g: &Graph,
    bodies: &BodyTerms,
    coordinates: &[String],
    p: &Printer,
    names: &HashMap<Id, String>,
) {
    let _ = writeln!(
        w,
        "Bodies (movable ones; fixed links merged into the body they hang from), each quantity in the body's frame:\n  \
         motion vectors [ω; v], force vectors [n; f] (moment about the body's origin; force), iX_λ from the parent λ to body i,\n  \
         recursive Newton–Euler at q̈ = 0:  vᵢ = iX_λ v_λ + Sᵢ q̇ᵢ,  aᵢ = iX_λ a_λ + vᵢ × Sᵢ q̇ᵢ  (v₀ = 0, a₀ = −g),\n  \
         fᵢ = Iᵢ aᵢ + vᵢ ×* Iᵢ vᵢ + Σ_children iX_jᵀ fⱼ,  bias c = C q̇ + g with cᵢ = Sᵢᵀ fᵢ,  F = Q − ∂V/∂q − c;\n  \
         a body's own Iᵢ aᵢ + vᵢ ×* Iᵢ vᵢ, where fewer operations, about its centre of mass c (Ī_C there):  ċᵢ = vᵢ.v + ωᵢ × c,\n  \
         c̈ᵢ = aᵢ.v̇ + ω̇ᵢ × c + ωᵢ × ċᵢ,  Lᵢ = Ī_C ωᵢ,  force m c̈ᵢ,  moment Ī_C ω̇ᵢ + ωᵢ × Lᵢ + c × m c̈ᵢ;\n  \
         composite rigid body:  Iᶜᵢ = Iᵢ + Σ_children iX_jᵀ Iᶜⱼ iX_j  (mass m, first moment h = m c, rotational Ī about the origin),\n  \
         {}\n  \
         Sums are named once below and by name wherever they recur.",
        mass_statement(bodies.mass_in_world)
    );
    for (i, (body, t)) in bodies.tree.iter().zip(&bodies.trace).enumerate() {
        let s = subscript(i + 1);
        let parent = body
            .parent
            .and_then(|k| bodies.names.get(k))
            .map_or_else(|| "world".to_string(), |n| format!("`{n}`"));
        let _ = writeln!(
            w,
            "  Body {} `{}` (parent {parent}): {}",
            i + 1,
            body.name,
            joint(body, coordinates, p)
        );
        placement(w, body, p);
        if let Some(t) = body.slid {
            let _ = writeln!(
                w,
                "    its frame slid by {} along the axis from the one described, where fewer \
                 translations are nonzero (the joint's motion commutes with the slide)",
                p.print(t)
            );
        }
        if let Some(t) = body.turned {
            let _ = writeln!(
                w,
                "    its frame turned by {} about the joint's axis from the one described, so that \
                 its child's joint frame is not turned (the joint's angle carries the turn)",
                p.print(t)
            );
        }
        let m = &body.inertia;
        let _ = writeln!(
            w,
            "    Iᵢ: m = {}, h = {}, Ī = {}",
            p.print(m.mass),
            vector(p, m.first_moment),
            matrix(p, &m.rotational)
        );
        motion(w, p, &s, t);
        let c = &t.composite;
        let _ = writeln!(
            w,
            "    Iᶜ{s}: m = {}, h = {}, Ī = {}",
            p.print(c.mass),
            vector(p, c.first_moment),
            matrix(p, &c.rotational)
        );
        for (id, label) in labelled(i, t) {
            if names.get(&id) == Some(&label) {
                let _ = writeln!(w, "      {label} = {}", definition(g, p, id));
            }
        }
    }
    let _ = writeln!(w);
}

/// A body's velocity, acceleration, motion at its centre of mass (where
/// its force was taken there) and force, subscripted `s`.
fn motion(w: &mut String, p: &Printer, s: &str, t: &Trace) {
    let line = |sym: &str, v: &Spatial, parts: [&str; 2]| {
        format!(
            "    {sym}{s} = [{}: {}; {}: {}]",
            parts[0],
            list(p, v.angular),
            parts[1],
            list(p, v.linear)
        )
    };
    let _ = writeln!(w, "{}", line("v", &t.velocity, ["ω", "v"]));
    let _ = writeln!(w, "{}", line("a", &t.acceleration, ["ω̇", "v̇"]));
    if let Some(center) = &t.center {
        let _ = writeln!(
            w,
            "    at the centre of mass c = {}, Ī_C = {}:\n      ċ{s} = {}, c̈{s} = {}, L{s} = {}",
            vector(p, center.com),
            matrix(p, &center.about_com),
            vector(p, center.velocity),
            vector(p, center.acceleration),
            vector(p, center.spin)
        );
    }
    let _ = writeln!(w, "{}", line("f", &t.force, ["n", "f"]));
}

/// The joint, its axis and its coordinates.
fn joint(body: &Body, coordinates: &[String], p: &Printer) -> String {
    let j = &body.joint;
    let names: Vec<&str> = j
        .coordinates()
        .filter_map(|c| coordinates.get(c).map(String::as_str))
        .collect();
    j.describe(&|id| p.print(id), &|v| vector(p, v), &names)
}

/// The joint frame in the parent's: `p` and `R`, omitted where they are
/// the origin and the identity.
fn placement(w: &mut String, body: &Body, p: &Printer) {
    let pl = &body.placement;
    let shown = |id: Id| p.print(id);
    let origin = pl.translation.iter().all(|&x| shown(x) == "0");
    let identity =
        (0..3).all(|r| (0..3).all(|c| shown(pl.rotation[r][c]) == if r == c { "1" } else { "0" }));
    if origin && identity {
        return;
    }
    let _ = writeln!(
        w,
        "    joint frame in the parent's: p = {}, R = {}",
        vector(p, pl.translation),
        if identity {
            "I".to_string()
        } else {
            matrix(p, &pl.rotation)
        }
    );
}

fn list(p: &Printer, v: V3) -> String {
    v.map(|x| p.print(x)).join(", ")
}

fn vector(p: &Printer, v: V3) -> String {
    format!("[{}]", list(p, v))
}

fn matrix(p: &Printer, m: &M3) -> String {
    let rows: Vec<String> = m.iter().map(|&row| vector(p, row)).collect();
    format!("[{}]", rows.join(", "))
}
