//! The human-readable derivation emitted as `DERIVATION`: the system written
//! the way the paper writes it, so that a change in the generated equations
//! reads as a change in mathematics in code review.

use super::derivation_saddle::order;
use crate::equations::gibbs_appell::{rank_one, RankOne};
use crate::equations::mass_inverse::{Factored, MassInverse};
use crate::equations::partition::Partition;
use crate::equations::Equations;
use crate::expr::print::{shared_subexpressions, subscript, Printer, Style};
use crate::expr::{Graph, Id};
use crate::model::{Energies, Level};
use crate::numeric::sparsity::Structure;
use std::collections::HashMap;
use std::fmt::Write;

/// The derivation of `eq` as plain text with Unicode mathematics.
pub fn text(eq: &Equations, partition: &Partition) -> String {
    let sys = &eq.system;
    let coordinates: Vec<String> = sys.coordinates.iter().map(ToString::to_string).collect();
    let parameters: Vec<String> = sys.parameters.iter().map(ToString::to_string).collect();
    let mut names: HashMap<Id, String> = sys
        .named
        .iter()
        .map(|(name, id)| (*id, name.clone()))
        .collect();
    // The rank-one Gibbs–Appell rows live in an extension of the system's
    // graph; everything is printed from that one graph.
    let rank_one = rank_one(eq, partition);
    let g = rank_one.as_ref().map_or(&sys.graph, |r| &r.graph);
    if let Some(bodies) = &sys.bodies {
        super::derivation_bodies::name_intermediates(g, bodies, &mut names);
    }
    let shared = shared_subexpressions(g, &printed_roots(eq, rank_one.as_ref()), &names, |i| {
        format!("ξ{}", subscript(i))
    });
    names.extend(shared.iter().map(|(id, name)| (*id, name.clone())));
    let p = Printer::new(g, &coordinates, &parameters, Style::Unicode).with_names(&names);
    let mut out = String::new();
    let w = &mut out;

    header(w, eq, &coordinates, &parameters, &shared, &p);
    if let Some(energies) = &sys.energies {
        energies_text(w, energies, &p);
    }
    if let Some(bodies) = &sys.bodies {
        super::derivation_bodies::text(w, g, bodies, &coordinates, &p, &names);
    }

    mass_text(w, eq, g, &coordinates, &p);
    let _ = writeln!(w, "Impressed forces  F(q, q̇, t):");
    for (c, &f) in coordinates.iter().zip(&sys.forces) {
        let _ = writeln!(w, "  F[{c}] = {}", p.print(f));
    }
    let _ = writeln!(w);

    if sys.constraints.is_empty() {
        let _ = writeln!(w, "No constraints: q̈ = M⁻¹ F.");
        let _ = writeln!(w, "  acceleration's {}", eq.strategy().describe());
        gaps_text(w, eq, g, &p, &coordinates);
        return out;
    }
    constraints_text(w, eq, g, &p, &coordinates);
    generalized_inverse(w, eq, &p, &coordinates, partition.rank);
    let _ = writeln!(w);
    gibbs_appell(w, eq, partition, rank_one.as_ref(), &p, &coordinates);
    gaps_text(w, eq, g, &p, &coordinates);
    out
}

/// The constraints as written, each with its level, and the rows of
/// `A q̈ = b` they are differentiated into.
fn constraints_text(
    w: &mut String,
    eq: &Equations,
    g: &Graph,
    p: &Printer,
    coordinates: &[String],
) {
    let _ = writeln!(w, "Constraints  φ(q, q̇, t) = 0:");
    for (i, c) in eq.system.constraints.iter().enumerate() {
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
    for (i, (a, &b)) in eq.a.iter().zip(&eq.b).enumerate() {
        let s = subscript(i + 1);
        let _ = writeln!(w, "  A{s} = [{}]", row_text(g, p, a, coordinates));
        let _ = writeln!(w, "  b{s} = {}", p.print(b));
    }
    let _ = writeln!(w);
}

/// The gaps of `unilateral: [..]` and their gradients, the rows the impact
/// map adds to the constraints' (nothing for a system without gaps).
fn gaps_text(w: &mut String, eq: &Equations, g: &Graph, p: &Printer, coordinates: &[String]) {
    let gaps = &eq.system.unilateral;
    if gaps.is_empty() {
        return;
    }
    let _ = writeln!(w);
    let _ = writeln!(
        w,
        "Unilateral gaps  g(q) ≥ 0 (contacts open where positive):"
    );
    for (i, gap) in gaps.iter().enumerate() {
        let _ = writeln!(w, "  g{} = {}", subscript(i + 1), p.print(gap.gap));
    }
    let _ = writeln!(w);
    let _ = writeln!(
        w,
        "Gap gradients  ∇g = ∂g/∂q (at an impact, the rows of the impulsive Gauss \
         principle: ∇gᵢ · q̇⁺ = −eᵢ ∇gᵢ · q̇⁻ for the impacting gaps, A q̇⁺ on the \
         constraints' velocity level):"
    );
    for (i, gap) in gaps.iter().enumerate() {
        let row = row_text(g, p, &gap.gradient, coordinates);
        let _ = writeln!(w, "  ∇g{} = [{row}]", subscript(i + 1));
    }
}

/// The name, coordinates, parameters and inputs; the named definitions and
/// the shared subexpressions.
fn header(
    w: &mut String,
    eq: &Equations,
    coordinates: &[String],
    parameters: &[String],
    shared: &[(Id, String)],
    p: &Printer,
) {
    let sys = &eq.system;
    let _ = writeln!(
        w,
        "{}: equations of motion derived by constrained_system!",
        sys.name
    );
    let _ = writeln!(w);
    let _ = writeln!(w, "Coordinates  q = ({})", coordinates.join(", "));
    let (parameters_only, inputs) = parameters.split_at(parameters.len() - sys.inputs);
    if !parameters_only.is_empty() {
        let _ = writeln!(w, "Parameters   {}", parameters_only.join(", "));
    }
    if !inputs.is_empty() {
        let _ = writeln!(w, "Inputs       u = ({})", inputs.join(", "));
    }
    let _ = writeln!(w);

    if !sys.named.is_empty() {
        let _ = writeln!(w, "Definitions (named wherever they occur below):");
        for (name, id) in &sys.named {
            let _ = writeln!(w, "  {name} = {}", p.print_expanded(*id));
        }
        let _ = writeln!(w);
    }
    if !shared.is_empty() {
        let _ = writeln!(
            w,
            "Shared subexpressions (each written out once, named where it recurs):"
        );
        for (id, name) in shared {
            let _ = writeln!(w, "  {name} = {}", p.print_expanded(*id));
        }
        let _ = writeln!(w);
    }
}

/// `M`: its diagonal, or the nonzero entries of its upper triangle.
fn mass_text(w: &mut String, eq: &Equations, g: &Graph, coordinates: &[String], p: &Printer) {
    let sys = &eq.system;
    let n = sys.dof();
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
}

/// A row of a k × n matrix: every entry when the row is short or mostly
/// nonzero; otherwise the nonzero entries by coordinate (`x1: 2·x1, …; 0
/// elsewhere`), so that a long chain's rows are as long as their
/// nonzeros, not as the chain.
fn row_text(g: &Graph, p: &Printer, ids: &[Id], coordinates: &[String]) -> String {
    let nonzero = ids.iter().filter(|&&e| !g.is_zero(e)).count();
    if ids.len() <= 8 || 2 * nonzero >= ids.len() {
        return ids
            .iter()
            .map(|&e| p.print(e))
            .collect::<Vec<_>>()
            .join(", ");
    }
    let entries: Vec<String> = ids
        .iter()
        .zip(coordinates)
        .filter(|(&e, _)| !g.is_zero(e))
        .map(|(&e, c)| format!("{c}: {}", p.print(e)))
        .collect();
    format!("{}; 0 elsewhere", entries.join(", "))
}

/// Every expression the derivation prints, for naming the shared ones.
fn printed_roots(eq: &Equations, rank_one: Option<&RankOne>) -> Vec<Id> {
    let sys = &eq.system;
    let mut roots: Vec<Id> = sys.named.iter().map(|(_, id)| *id).collect();
    if let Some(bodies) = &sys.bodies {
        roots.extend(super::derivation_bodies::roots(bodies));
    }
    if let Some(e) = &sys.energies {
        roots.extend(e.kinetic.iter().chain(&e.potential).chain(&e.applied));
    }
    roots.extend(sys.mass.iter().flatten());
    roots.extend(&sys.forces);
    roots.extend(sys.constraints.iter().map(|c| c.phi));
    roots.extend(eq.a.iter().flatten());
    roots.extend(&eq.b);
    for gap in &sys.unilateral {
        roots.push(gap.gap);
        roots.extend(&gap.gradient);
    }
    if let MassInverse::Symbolic(d) = &eq.mass_inverse {
        roots.extend(&d.unconstrained);
        roots.extend(d.gram.iter().flatten());
        roots.extend(&d.residual);
        roots.extend(&d.acceleration);
        roots.extend(&d.force);
    }
    if let Some(r) = rank_one {
        for (row, rhs) in &r.rows {
            roots.extend(row);
            roots.push(*rhs);
        }
    }
    roots
}

/// T, V and Q as written, and how M and F follow from them.
fn energies_text(w: &mut String, energies: &Energies, p: &Printer) {
    let _ = writeln!(w, "Energies and generalized forces:");
    if let Some(t) = energies.kinetic {
        let _ = writeln!(w, "  T = {}", p.print(t));
    }
    if let Some(v) = energies.potential {
        let _ = writeln!(w, "  V = {}", p.print(v));
    }
    let q: Vec<String> = energies.applied.iter().map(|&e| p.print(e)).collect();
    let _ = writeln!(w, "  Q = [{}]", q.join(", "));
    let _ = writeln!(
        w,
        "Lagrange's equations d/dt(∂T/∂q̇) − ∂T/∂q = Q − ∂V/∂q give M q̈ = F with"
    );
    let _ = match energies.kinetic {
        Some(_) => writeln!(
            w,
            "  M = ∂²T/∂q̇∂q̇ᵀ,  F = Q − ∂V/∂q + ∂T/∂q − (∂²T/∂q̇∂qᵀ) q̇ − ∂²T/∂q̇∂t:"
        ),
        None => writeln!(w, "  M as given,  F = Q − ∂V/∂q:"),
    };
    let _ = writeln!(w);
}

/// The explicit Gibbs–Appell system: its structure, and for r = 1 every
/// entry (Appell's particle with e = {x} gives the paper's eq. 33).
fn gibbs_appell(
    w: &mut String,
    eq: &Equations,
    partition: &Partition,
    rank_one: Option<&RankOne>,
    p: &Printer,
    coordinates: &[String],
) {
    let r = partition.rank;
    let coupled = !eq.mass_inverse.is_diagonal();
    let eliminated: Vec<String> = partition
        .eliminated
        .iter()
        .map(|&e| format!("q̈[{}]", coordinates[e]))
        .collect();
    let measured = measured_at(partition);
    let _ = writeln!(
        w,
        "Explicit Gibbs–Appell equation ({}):  rank A = {r} ({measured}); eliminated: {}",
        if coupled { "eq. 37" } else { "eq. 18" },
        if eliminated.is_empty() {
            "none".to_string()
        } else {
            eliminated.join(", ")
        }
    );
    let _ = writeln!(
        w,
        "  [[A_e, A_I], [0, B]] q̈ = [b, F_I − Rᵀ F_e + {}A_e⁺ b],  R = A_e⁺ A_I,  A_e⁺ = (A_eᵀ A_e)⁻¹ A_eᵀ,",
        if coupled { "(Rᵀ M_ee − M_Ie) " } else { "Rᵀ M_ee " }
    );
    let _ = writeln!(
        w,
        "  B = M_II + Rᵀ M_ee R{}; {} independent row{} of A q̈ = b on top{}; columns in the order of q",
        if coupled { " − M_Ie R − Rᵀ M_Ieᵀ" } else { "" },
        r,
        if r == 1 { "" } else { "s" },
        if eq.a.len() > r { " (chosen at run time)" } else { "" }
    );
    if let Some(RankOne { rows, .. }) = rank_one {
        rank_one_rows(w, eq, rows, p);
    }
}

/// Where the partition's rank was measured: at how many consistent states
/// (and at how many of them it was lower), or off the constraint surface.
fn measured_at(partition: &Partition) -> String {
    if partition.on_surface && partition.lower > 0 {
        // Said only where it happens, so that other models' text is as it was.
        format!(
            "at {} consistent states; lower at {} of them and the {} that checked it: \
             branch points, decided at run time",
            partition.states, partition.lower, partition.checked
        )
    } else if partition.on_surface {
        format!("at {} consistent states", partition.states)
    } else {
        "off the constraint surface (no consistent state was found)".to_string()
    }
}

/// For rank 1, the system's every row: the row of `A q̈ = b` on top (or
/// where several could be, which is chosen at run time), then the rows of
/// `B` with their right-hand sides.
fn rank_one_rows(w: &mut String, eq: &Equations, rows: &[(Vec<Id>, Id)], p: &Printer) {
    let line = |ids: &[Id]| {
        ids.iter()
            .map(|&x| p.print(x))
            .collect::<Vec<_>>()
            .join(",  ")
    };
    if eq.a.len() == 1 {
        let _ = writeln!(w, "  row 1:  [{}]  |  {}", line(&eq.a[0]), p.print(eq.b[0]));
    } else {
        let _ = writeln!(
            w,
            "  row 1:  one of the rows of A q̈ = b with A_ie ≠ 0, chosen at run time"
        );
    }
    for (i, (row, rhs)) in rows.iter().enumerate() {
        let _ = writeln!(w, "  row {}:  [{}]  |  {}", i + 2, line(row), p.print(*rhs));
    }
}

/// How `λ` is solved from `S λ = r` (S = A M⁻¹ Aᵀ, r = b − A a, S with the given
/// compile-time structure).
fn multiplier_rule(w: &mut String, structure: &Structure, rank: usize) {
    let k = structure.len();
    match k {
        0 => {}
        1 => {
            let _ = writeln!(
                w,
                "  λ₁ = r₁ / S₁₁; where S vanishes (or underflows), \
                 q̈ is checked against A q̈ = b at run time and, if it fails, recomputed by \
                 the row-scaled Moore–Penrose form"
            );
        }
        _ => {
            let _ = writeln!(
                w,
                "  λ by LDLᵀ of S on its compile-time pattern, eliminating \
                 constraints in the order {}\n  ({} of {} subdiagonal entries of L nonzero); \
                 rows with sin²θ = dⱼ/Sⱼⱼ < max(1e-6, 64ε) are dropped (a {{1}}-inverse)\n  \
                 when at least rank A = {rank} rows remain or every row still holds to 1000ε \
                 (checked at run time); otherwise q̈ is recomputed by the row-scaled Moore–Penrose form",
                order(structure, |i| format!("φ{}", subscript(i + 1))),
                fill(structure),
                k * (k - 1) / 2
            );
        }
    }
}

/// How the solved system was scaled (`crate::equations::mass_inverse::Symbolic`): the
/// rows of `A q̈ = b` divided by their numeric content, `M` by a common
/// mass. S, r and λ below are those of the scaled system; q̈ is the same.
fn scaling_text(w: &mut String, d: &crate::equations::mass_inverse::Symbolic, p: &Printer) {
    let scaled = d.scale.iter().any(|s| !s.is_one());
    if !scaled && d.common_mass.is_none() {
        return;
    }
    let mut what = Vec::new();
    if scaled {
        let diagonal: Vec<String> = d.scale.iter().map(ToString::to_string).collect();
        what.push(format!(
            "each row of A q̈ = b by its numeric content (D = diag({}))",
            diagonal.join(", ")
        ));
    }
    if let Some(m) = d.common_mass {
        what.push(format!("M by its common mass μ = {}", p.print(m)));
    }
    let (s, force) = match (scaled, d.common_mass.is_some()) {
        (true, true) => ("S = μ D A M⁻¹ Aᵀ D,  r = D (b − A a)", "Fᶜ = μ (D A)ᵀ λ"),
        (true, false) => ("S = D A M⁻¹ Aᵀ D,  r = D (b − A a)", "Fᶜ = (D A)ᵀ λ"),
        (false, _) => ("S = μ A M⁻¹ Aᵀ", "Fᶜ = μ Aᵀ λ"),
    };
    let _ = writeln!(
        w,
        "  Solved scaled, the same q̈ in fewer operations: {}.\n  Below {s},  {force}:",
        what.join(", and ")
    );
}

/// The number of structurally nonzero subdiagonal entries of `L`.
fn fill(structure: &Structure) -> usize {
    let k = structure.len();
    (0..k)
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .filter(|&(i, j)| structure.fill[i][j])
        .count()
}

/// Gauss's principle for a configuration-dependent `M`, as generated.
fn factored(w: &mut String, f: &Factored, coordinates: &[String], rank: usize) {
    let n = f.mass.len();
    let (m, forces, lead, pivot) = if f.auxiliary.is_some() {
        (
            "M_A",
            "F_A",
            "",
            "the runtime's dense solve (all rows of A) answers",
        )
    } else {
        (
            "M",
            "F",
            "M depends on q and is not diagonal: ",
            "M is not positive definite there (Err, as Cholesky fails)",
        )
    };
    let _ = writeln!(
        w,
        "  {lead}P {m} Pᵀ = L D Lᵀ on its compile-time pattern, \
         eliminating coordinates in the order {}\n  ({} of {} subdiagonal entries of L nonzero); \
         where a pivot dⱼ ≤ 0, {pivot};",
        order(&f.mass, |i| coordinates[i].clone()),
        fill(&f.mass),
        n * n.saturating_sub(1) / 2,
    );
    if f.gram.is_empty() {
        let _ = writeln!(w, "  a = {m}⁻¹ {forces} by substitution");
        multiplier_rule(w, &f.gram, rank);
        let _ = writeln!(w, "  q̈ = a");
        return;
    }
    let _ = writeln!(
        w,
        "  Y = L⁻¹ P Aᵀ and z = L⁻¹ P {forces} by forward substitution, \
         S = Yᵀ D⁻¹ Y (= A {m}⁻¹ Aᵀ), r = b − Yᵀ D⁻¹ z (= b − A a)"
    );
    multiplier_rule(w, &f.gram, rank);
    let _ = writeln!(
        w,
        "  q̈ = Pᵀ L⁻ᵀ D⁻¹ (z + Y λ) by one back substitution (= a + {m}⁻¹ Aᵀ λ),  Fᶜ = Aᵀ λ"
    );
}

/// Why a singular `M` is solved through Udwadia & Schutte's auxiliary
/// system, and which rows `A_R` of `A` complete its rank.
fn auxiliary_text(w: &mut String, f: &Factored) {
    let rows = f.auxiliary.as_ref().map_or_else(String::new, |x| {
        let listed: Vec<String> = x.rows.iter().map(ToString::to_string).collect();
        match listed.len() {
            1 => format!("is row {} of A", listed[0]),
            _ => format!("are rows {} of A", listed.join(", ")),
        }
    });
    let _ = writeln!(
        w,
        "  M is singular (positive semi-definite) and [M; A] has full column rank at consistent states:\n  \
         Udwadia & Schutte's auxiliary system M_A = M + s A_RᵀA_R, F_A = F + s A_Rᵀ b_R (s = tr M / ‖A_R‖²)\n  \
         has the same q̈ and, as A q̈ = b, the same λ; A_R {rows}, the sparsest rows that\n  \
         complete M's rank. It is solved for M_A, F_A on the pattern of M + A_RᵀA_R:"
    );
}

/// The generalized-inverse equation (eq. 26) as it is solved.
fn generalized_inverse(
    w: &mut String,
    eq: &Equations,
    p: &Printer,
    coordinates: &[String],
    rank: usize,
) {
    let g = &eq.system.graph;
    let k = eq.a.len();
    let _ = writeln!(
        w,
        "Generalized-inverse equation (eq. 26)  M q̈ = F + Aᵀ λ,  S λ = r,  S = A M⁻¹ Aᵀ,  r = b − A a,  a = M⁻¹ F:"
    );
    // The strategy `acceleration` carries out, in the words of its `gauss`.
    let strategy = eq.strategy();
    let _ = writeln!(w, "  acceleration's {}", strategy.describe());
    let d = match &eq.mass_inverse {
        MassInverse::Symbolic(d) => d,
        MassInverse::Factored(f) => {
            factored(w, f, coordinates, rank);
            super::derivation_saddle::text(w, f, coordinates, strategy);
            return;
        }
        MassInverse::Auxiliary(f) => {
            auxiliary_text(w, f);
            factored(w, f, coordinates, rank);
            super::derivation_saddle::text(w, f, coordinates, strategy);
            return;
        }
    };
    for (c, &a) in coordinates.iter().zip(&d.unconstrained) {
        let _ = writeln!(w, "  a[{c}] = {}", p.print(a));
    }
    scaling_text(w, d, p);
    for i in 0..k {
        for j in i..k {
            if !g.is_zero(d.gram[i][j]) {
                let _ = writeln!(
                    w,
                    "  S{}{} = {}",
                    subscript(i + 1),
                    subscript(j + 1),
                    p.print(d.gram[i][j])
                );
            }
        }
    }
    for i in 0..k {
        let _ = writeln!(w, "  r{} = {}", subscript(i + 1), p.print(d.residual[i]));
    }
    multiplier_rule(w, &d.structure, rank);
    for (c, &e) in coordinates.iter().zip(&d.acceleration) {
        let _ = writeln!(w, "  q̈[{c}] = {}", p.print(e));
    }
    for (c, &e) in coordinates.iter().zip(&d.force) {
        let _ = writeln!(w, "  Fᶜ[{c}] = {}", p.print(e));
    }
}
