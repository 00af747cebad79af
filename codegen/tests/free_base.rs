//! A floating base is found however it is written: `free(..)` on the world,
//! `free(..)` under a body fixed to the world, or a URDF's `floating` joint
//! from a `world` link. The same robot — a trunk on one three-joint leg,
//! its foot held at a point — gives the same solve each way: the foot's
//! rows in the base's axes and the leg eliminated through them
//! (`emit::mass_inverse::factored::legs`), at the same operation count.
//! `tests/free_base.rs` compares their `q̈`.

use constrained_codegen::tools::op_count;
use constrained_codegen::{expand_with, Options};

/// The leg's bodies below the trunk and the foot's rows, common to the
/// `bodies` forms (the numbers of `tests/data/one_leg.urdf`).
const LEG: &str = "
    hip {
        parent: trunk,
        joint: revolute(haa, [1.0, 0.0, 0.0]),
        xyz: [0.1946, 0.0875, 0.0],
        mass: 0.149,
        com: [0.0, 0.014, 0.0],
        inertia: diag[4.0e-5, 7.0e-5, 4.0e-5],
    },
    upper {
        parent: hip,
        joint: revolute(hfe, [0.0, 1.0, 0.0]),
        xyz: [0.0, 0.014, 0.0],
        mass: 0.149,
        com: [0.0, 0.016, -0.078],
        inertia: diag[4.2e-4, 4.1e-4, 2.4e-5],
    },
    lower {
        parent: upper,
        joint: revolute(kfe, [0.0, 1.0, 0.0]),
        xyz: [0.0, 0.037, -0.16],
        mass: 0.031,
        com: [0.0, 0.007, -0.079],
        inertia: diag[1.2e-4, 1.2e-4, 2.1e-6],
    },
";

/// The trunk on `free(..)`, its parent and that parent's own body (if any)
/// written by `mount`.
fn bodies(mount: &str, parent: &str) -> String {
    format!(
        "{mount}
        trunk {{
            parent: {parent},
            joint: free(base_x, base_y, base_z, base_qw, base_qx, base_qy, base_qz),
            mass: 1.16,
            com: [0.01, -0.005, 0.002],
            inertia: diag[0.0058, 0.0194, 0.0246],
        }},
        {LEG}"
    )
}

/// The system with its tree given by `tree` (a `bodies: [..]` or `urdf:`
/// section).
fn system(tree: &str) -> proc_macro2::TokenStream {
    format!(
        "struct OneLeg {{
            parameters: [px, py],
            inputs: [t1, t2, t3],
            {tree},
            forces: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, t1, t2, t3],
            constraints: [position(lower, [0.0, 0.008, -0.16]) == [px, py, 0.0]],
        }}"
    )
    .parse()
    .expect("the model is tokens")
}

/// The operations of `q̈`, whether the leg is eliminated through its foot
/// (`__ljd0`, the leg's determinant, in `gauss`), and the text of
/// `gauss`.
fn solve(tree: &str) -> (usize, bool, String) {
    let expanded = expand_with(system(tree), Options { jacobians: false }).expect("it expands");
    let text = expanded.to_string();
    let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
    let ops = op_count::acceleration(&file)
        .expect("a generated solve")
        .total();
    let gauss = &text[text.find("fn gauss <").expect("a generated gauss")..];
    let gauss = gauss[..gauss[1..].find(" fn ").map_or(gauss.len(), |e| e + 1)].to_string();
    (ops, gauss.contains("let __ljd0 ="), gauss)
}

#[test]
fn a_floating_base_is_found_however_it_is_written() {
    let on_world = solve(&format!("bodies: [{}]", bodies("", "world")));
    let under_fixed = solve(&format!(
        "bodies: [{}]",
        bodies("mount { joint: fixed },", "mount")
    ));
    // A body fixed to the world is the world, whatever its mass: nothing
    // of it moves.
    let heavy_mount = solve(&format!(
        "bodies: [{}]",
        bodies(
            "mount { joint: fixed, mass: 2.0, inertia: diag[0.1, 0.1, 0.1] },",
            "mount"
        )
    ));
    let urdf = solve("urdf: \"../tests/data/one_leg.urdf\"");
    assert!(on_world.1, "the leg is eliminated through its foot");
    for (how, other) in [
        ("under a fixed body", under_fixed),
        ("under a fixed body with mass", heavy_mount),
        ("from a URDF's world link", urdf),
    ] {
        assert_eq!(
            (other.0, other.1),
            (on_world.0, on_world.1),
            "{how}: operations per q̈, legs solve"
        );
        // Not only as many operations: the same solve, statement by
        // statement (the coordinates have the same names each way).
        assert!(other.2 == on_world.2, "{how}: the same `gauss`");
    }
}

/// A fixed body that places the base's frame elsewhere in the world makes
/// the base's coordinates those of that frame: the rows `p + R̂ r = c`
/// of the foot in the base's axes do not hold with `p` the coordinates,
/// and the general solve answers (`tests/free_base.rs` checks its `q̈`).
#[test]
fn a_base_placed_by_a_fixed_body_takes_the_general_solve() {
    let (_, legs, _) = solve(&format!(
        "bodies: [{}]",
        bodies("mount { joint: fixed, xyz: [0.0, 0.0, 0.3] },", "mount")
    ));
    assert!(!legs, "no legs solve under a displaced frame");
}
