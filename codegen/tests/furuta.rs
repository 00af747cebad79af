//! A Furuta pendulum written as a newcomer writes it — the bob's Cartesian
//! position as definitions, `T` and `V` from them, a torque input on the
//! arm — derives the textbook's equations: `M = [[J + m r² + m l² sin²α,
//! m r l cos α], [m r l cos α, m l²]]` and forces without the arm angle θ
//! (the system is symmetric about the vertical axis), both in the code's
//! expressions and in `DERIVATION`.

use constrained_codegen::analyse;
use constrained_codegen::emit::derivation;
use constrained_codegen::expr::{Graph, Id, Sym};

fn furuta() -> proc_macro2::TokenStream {
    quote::quote! {
        pub struct Furuta {
            coordinates: [th, al],
            parameters: [jr, m, r, l, g],
            inputs: [tau],
            definitions: [
                px = r * th.cos() - l * al.sin() * th.sin(),
                py = r * th.sin() + l * al.sin() * th.cos(),
                pz = l * al.cos(),
            ],
            kinetic_energy: jr * dot(th).powi(2) / 2.0
                + m * (dt(px).powi(2) + dt(py).powi(2) + dt(pz).powi(2)) / 2.0,
            potential_energy: m * g * pz,
            forces: [tau, 0.0],
        }
    }
}

/// Values of the coordinates, velocities and parameters (jr, m, r, l, g)
/// and the input.
fn env(q: [f64; 2], qd: [f64; 2]) -> impl Fn(Sym) -> f64 {
    let params = [0.02, 0.3, 0.25, 0.4, 9.81, 0.7];
    move |s| match s {
        Sym::Coord(i) => q[i],
        Sym::Vel(i) => qd[i],
        Sym::Param(i) => params[i],
        _ => f64::NAN,
    }
}

fn free_of_theta(g: &Graph, id: Id) -> bool {
    !g.mentions(id, |s| s == Sym::Coord(0))
}

#[test]
fn the_mass_matrix_is_the_textbooks() {
    let eq = analyse(furuta()).expect("a valid system");
    let g = &eq.system.graph;
    let m = &eq.system.mass;
    for entry in m.iter().flatten() {
        assert!(free_of_theta(g, *entry), "θ in M");
    }
    // m l² is a constant: no coordinate at all.
    assert!(!g.mentions(m[1][1], |s| matches!(s, Sym::Coord(_))));
    let (jr, mm, r, l) = (0.02, 0.3, 0.25, 0.4);
    for (th, al) in [(0.3, -1.1), (2.0, 0.4), (-0.7, 2.9)] {
        let at = env([th, al], [0.0, 0.0]);
        let value = |id: Id| g.eval(&[id], &at)[0];
        let textbook = [
            [
                jr + mm * r * r + mm * l * l * al.sin().powi(2),
                mm * r * l * al.cos(),
            ],
            [mm * r * l * al.cos(), mm * l * l],
        ];
        for i in 0..2 {
            for j in 0..2 {
                assert!((value(m[i][j]) - textbook[i][j]).abs() < 1e-14);
            }
        }
    }
}

#[test]
fn the_forces_do_not_depend_on_the_arm_angle() {
    let eq = analyse(furuta()).expect("a valid system");
    let g = &eq.system.graph;
    let (mm, r, l, grav, tau) = (0.3, 0.25, 0.4, 9.81, 0.7);
    for f in &eq.system.forces {
        assert!(free_of_theta(g, *f), "θ in F");
    }
    // Lagrange's equations by hand:
    // F_θ = τ − 2 m l² sin α cos α θ̇ α̇ + m r l sin α α̇²,
    // F_α = m l² sin α cos α θ̇² + m g l sin α.
    for (q, qd) in [([0.3, -1.1], [0.5, 1.5]), ([2.0, 0.4], [-1.0, 0.2])] {
        let at = env(q, qd);
        let (s, c) = (q[1].sin(), q[1].cos());
        let expected = [
            tau - 2.0 * mm * l * l * s * c * qd[0] * qd[1] + mm * r * l * s * qd[1] * qd[1],
            mm * l * l * s * c * qd[0] * qd[0] + mm * grav * l * s,
        ];
        let values = g.eval(&eq.system.forces, &at);
        for i in 0..2 {
            assert!(
                (values[i] - expected[i]).abs() < 1e-13,
                "{values:?} vs {expected:?}"
            );
        }
    }
}

#[test]
fn the_derivation_reads_as_the_textbook() {
    let eq = analyse(furuta()).expect("a valid system");
    let text = derivation::text(&eq, &eq.partition);
    for line in [
        // T with both velocities of the bob by their names.
        "T = jr·ṫh²/2 + m·(dt(px)² + dt(py)² + l²·ȧl²·sin(al)²)/2",
        "M[th, th] = jr + m·(l²·sin(al)² + r²)",
        "M[th, al] = m·r·l·cos(al)",
        "M[al, al] = m·l²",
        "F[th] = tau + m·l·ȧl·sin(al)·(r·ȧl − 2·l·ṫh·cos(al))",
        "F[al] = m·l·sin(al)·(g + l·ṫh²·cos(al))",
    ] {
        assert!(text.contains(line), "{line}\nnot in\n{text}");
    }
}

/// The identity is applied where it makes the whole matrix (or `F`)
/// cheaper, shared subexpressions counted once, not where one entry alone
/// gets shorter: the 8-link pendulum in joint angles, whose `M` entries
/// share their terms, costs at most what it costs with no identity applied
/// at all (4,673 operations per `q̈`, measured with the identity switched
/// off). Judged entry by entry it had grown to 5,441. With the addition
/// theorems, decided on `M` and `F` together, it is 4,658; decided on `M`
/// alone, whose products the forces still needed, it was 4,953.
#[test]
fn the_identity_never_makes_the_pendulums_acceleration_dearer() {
    use constrained_codegen::tools::{fixtures::joint_angle_pendulum, op_count};
    let tokens: proc_macro2::TokenStream = joint_angle_pendulum("Pendulum", 8)
        .parse()
        .expect("the fixture is tokens");
    let expanded = constrained_codegen::expand(tokens).expect("the pendulum expands");
    let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
    let ops = op_count::acceleration(&file)
        .expect("a straight-line acceleration")
        .total();
    assert!(ops <= 4_658, "{ops} operations per q̈");
}

/// The expansion of the N-link pendulum in joint angles (the fixture's
/// Cartesian definitions `xᵢ = xᵢ₋₁ + Lᵢ sin φᵢ`, `φᵢ = θ₁ + … + θᵢ`).
fn joint_angle_chain(links: usize) -> proc_macro2::TokenStream {
    constrained_codegen::tools::fixtures::joint_angle_pendulum("Pendulum", links)
        .parse()
        .expect("the fixture is tokens")
}

/// A double pendulum in joint angles reads as the textbook's:
/// `M₁₂ = m₂·l₁·l₂·cos θ₂ + m₂·l₂²` and a Coriolis force `∝ sin θ₂`, not
/// `cos θ₁·cos(θ₁ + θ₂) + sin θ₁·sin(θ₁ + θ₂)` (the addition theorems,
/// `expr::trig::join_angle_sums`). The fixture's `m₂·l₁·l₂ = 1.2·1.05·1.1 =
/// 693/500` and `m₂·l₂² = 363/250`.
#[test]
fn a_chain_in_joint_angles_reads_its_relative_angle() {
    let eq = analyse(joint_angle_chain(2)).expect("a valid system");
    let g = &eq.system.graph;
    for entry in eq.system.mass.iter().flatten() {
        assert!(!g.mentions(*entry, |s| s == Sym::Coord(0)), "θ₁ in M");
    }
    let text = derivation::text(&eq, &eq.partition);
    for line in [
        "M[th1, th1] = 693·cos(th2)/250 + 15951/4000",
        "M[th1, th2] = 693·cos(th2)/500 + 363/250",
        "F[th2] = −33·g·sin(p2)/25 − 693·ṫh1²·sin(th2)/500",
    ] {
        assert!(text.contains(line), "{line}\nnot in\n{text}");
    }
    // The Coriolis and centrifugal forces of the first joint: θ₂ only.
    let at = |q: [f64; 2], qd: [f64; 2]| {
        move |s| match s {
            Sym::Coord(i) => q[i],
            Sym::Vel(i) => qd[i],
            _ => 0.0, // g = 0
        }
    };
    let f0 = eq.system.forces[0];
    let (qd1, qd2) = (0.7, -1.3);
    for (th1, th2) in [(0.3, 1.1), (-2.0, 0.4)] {
        let value = g.eval(&[f0], &at([th1, th2], [qd1, qd2]))[0];
        let textbook = 1.386 * qd2 * th2.sin() * (2.0 * qd1 + qd2);
        assert!(
            (value - textbook).abs() < 1e-14,
            "{value} against {textbook}"
        );
    }
}

/// The addition theorems halve the short chains' `q̈`: 73 → 38 operations
/// for 2 links, 251 → 130 for 3, 601 → 288 for 4 (measured before them).
#[test]
fn angle_sums_halve_the_short_chains_acceleration() {
    use constrained_codegen::tools::op_count;
    for (links, bound) in [(2, 38), (3, 130), (4, 288)] {
        let expanded = constrained_codegen::expand(joint_angle_chain(links)).expect("expands");
        let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
        let ops = op_count::acceleration(&file)
            .expect("a straight-line acceleration")
            .total();
        assert!(ops <= bound, "{links} links: {ops} operations per q̈");
    }
}
