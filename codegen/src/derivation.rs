//! The human-readable derivation emitted as `DERIVATION`: the system written
//! the way the paper writes it, so that a change in the generated equations
//! reads as a change in mathematics in code review.

use crate::derive::Equations;
use crate::expr::Id;
use crate::model::Level;
use crate::print::{subscript, Printer, Style};
use std::fmt::Write;

/// The derivation of `eq` as plain text with Unicode mathematics.
pub fn text(eq: &Equations) -> String {
    let sys = &eq.system;
    let coordinates: Vec<String> = sys.coordinates.iter().map(ToString::to_string).collect();
    let parameters: Vec<String> = sys.parameters.iter().map(ToString::to_string).collect();
    let p = Printer::new(&sys.graph, &coordinates, &parameters, Style::Unicode);
    let g = &sys.graph;
    let mut out = String::new();
    let w = &mut out;
    let n = sys.dof();

    let _ = writeln!(
        w,
        "{}: equations of motion derived by constrained_system!",
        sys.name
    );
    let _ = writeln!(w);
    let _ = writeln!(w, "Coordinates  q = ({})", coordinates.join(", "));
    if !parameters.is_empty() {
        let _ = writeln!(w, "Parameters   {}", parameters.join(", "));
    }
    let _ = writeln!(w);

    let diagonal = (0..n).all(|i| (0..n).all(|j| i == j || g.is_zero(sys.mass[i][j])));
    if diagonal {
        let entries: Vec<String> = (0..n).map(|i| p.print(sys.mass[i][i])).collect();
        let _ = writeln!(w, "Mass matrix  M = diag({})", entries.join(", "));
    } else {
        let _ = writeln!(
            w,
            "Mass matrix  M (symmetric; upper triangle, nonzero entries):"
        );
        for i in 0..n {
            for j in i..n {
                if !g.is_zero(sys.mass[i][j]) {
                    let (a, b) = (&coordinates[i], &coordinates[j]);
                    let _ = writeln!(w, "  M[{a}, {b}] = {}", p.print(sys.mass[i][j]));
                }
            }
        }
    }
    let _ = writeln!(w);

    let _ = writeln!(w, "Impressed forces  F(q, q̇, t):");
    for (c, &f) in coordinates.iter().zip(&sys.forces) {
        let _ = writeln!(w, "  F[{c}] = {}", p.print(f));
    }
    let _ = writeln!(w);

    if sys.constraints.is_empty() {
        let _ = writeln!(w, "No constraints: q̈ = M⁻¹ F.");
        return out;
    }
    let _ = writeln!(w, "Constraints  φ(q, q̇, t) = 0:");
    for (i, c) in sys.constraints.iter().enumerate() {
        let how = match c.level {
            Level::Position => "position level: differentiated twice",
            Level::Velocity => "velocity level: differentiated once",
        };
        let _ = writeln!(w, "  φ{} = {}    ({how})", subscript(i + 1), p.print(c.phi));
    }
    let _ = writeln!(w);

    let _ = writeln!(
        w,
        "Constraint equations  A q̈ = b  (ψ = Dφ or D²φ, A = ∂ψ/∂q̈, b = −ψ at q̈ = 0):"
    );
    let row = |ids: &[Id]| {
        ids.iter()
            .map(|&e| p.print(e))
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (i, (a, &b)) in eq.a.iter().zip(&eq.b).enumerate() {
        let s = subscript(i + 1);
        let _ = writeln!(w, "  A{s} = [{}]", row(a));
        let _ = writeln!(w, "  b{s} = {}", p.print(b));
    }
    out
}
