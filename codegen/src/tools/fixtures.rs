//! Systems generated as DSL text, for benchmarks and tests that need a family
//! of sizes (the macro itself cannot loop over N).

use std::fmt::Write;

/// A planar N-link pendulum in Cartesian coordinates, as `constrained_system!`
/// input: point masses `mᵢ = 1 + 0.1 i` at the joints of rods
/// `Lᵢ = 1 + 0.05 i`, the first rod pivoting at the origin, gravity `g` along
/// −y. 2N coordinates, N position-level constraints. The masses and lengths
/// are those of the independent reference vectors the chain's tests use.
pub fn planar_chain(name: &str, links: usize) -> String {
    let mut coordinates = Vec::new();
    let mut masses = Vec::new();
    let mut forces = Vec::new();
    let mut constraints = Vec::new();
    for i in 1..=links {
        coordinates.push(format!("x{i}, y{i}"));
        let m = 1.0 + 0.1 * i as f64;
        let l = 1.0 + 0.05 * i as f64;
        masses.push(format!("{m:?}, {m:?}"));
        forces.push(format!("0.0, -{m:?} * g"));
        let (px, py) = if i == 1 {
            ("0.0".to_string(), "0.0".to_string())
        } else {
            (format!("x{}", i - 1), format!("y{}", i - 1))
        };
        constraints.push(format!(
            "(x{i} - {px}).powi(2) + (y{i} - {py}).powi(2) == {l:?}.powi(2)"
        ));
    }
    let mut out = String::new();
    let _ = write!(
        out,
        "/// A planar {links}-link pendulum in Cartesian coordinates.\n\
         pub struct {name} {{\n\
         coordinates: [{}],\n\
         parameters: [g],\n\
         mass: diag[{}],\n\
         forces: [{}],\n\
         constraints: [{}],\n\
         }}",
        coordinates.join(", "),
        masses.join(", "),
        forces.join(", "),
        constraints.join(", "),
    );
    out
}

/// A planar N-link pendulum in its joint angles, from its energies, as
/// `constrained_system!` input: the same masses and lengths as
/// [`planar_chain`], `φᵢ = θ₁ + … + θᵢ` the absolute angle of rod i, the
/// joints at `xᵢ = xᵢ₋₁ + Lᵢ sin φᵢ`, `yᵢ = yᵢ₋₁ − Lᵢ cos φᵢ`,
/// `T = Σ mᵢ (ẋᵢ² + ẏᵢ²)/2`, `V = g Σ mᵢ yᵢ`. N coordinates, a dense
/// `M(q)` and O(N²) velocity products in `F`; no constraints.
pub fn joint_angle_pendulum(name: &str, links: usize) -> String {
    let mut coordinates = Vec::new();
    let mut definitions = Vec::new();
    let mut kinetic = Vec::new();
    let mut potential = Vec::new();
    for i in 1..=links {
        coordinates.push(format!("th{i}"));
        let m = 1.0 + 0.1 * i as f64;
        let l = 1.0 + 0.05 * i as f64;
        let (angle, x, y) = if i == 1 {
            ("th1".to_string(), String::new(), String::new())
        } else {
            (
                format!("p{} + th{i}", i - 1),
                format!("x{} + ", i - 1),
                format!("y{} ", i - 1),
            )
        };
        definitions.push(format!("p{i} = {angle}"));
        definitions.push(format!("x{i} = {x}{l:?} * p{i}.sin()"));
        definitions.push(format!("y{i} = {y}- {l:?} * p{i}.cos()"));
        kinetic.push(format!("{m:?} * (dt(x{i}).powi(2) + dt(y{i}).powi(2))"));
        potential.push(format!("{m:?} * y{i}"));
    }
    let mut out = String::new();
    let _ = write!(
        out,
        "/// A planar {links}-link pendulum in joint angles, from its energies.\n\
         pub struct {name} {{\n\
         coordinates: [{}],\n\
         parameters: [g],\n\
         definitions: [{}],\n\
         kinetic_energy: ({}) / 2.0,\n\
         potential_energy: g * ({}),\n\
         }}",
        coordinates.join(", "),
        definitions.join(", "),
        kinetic.join(" + "),
        potential.join(" + "),
    );
    out
}

/// A vehicle-sized model with many definitions, as `constrained_system!`
/// input: 8 coordinates (a planar body `x, y, yaw` and five wheel and
/// suspension coordinates) with unit masses, forces computed through
/// `definitions` intermediate quantities (each definition combines the two
/// before it with a coordinate's trigonometry or a velocity, the way a
/// tyre and suspension model chains slip, load and force), and two
/// constraints (a nonholonomic no-side-slip condition and a holonomic
/// linkage through a definition). For measuring how the derivation's text
/// grows with a large input.
pub fn definition_heavy(name: &str, definitions: usize) -> String {
    let coordinates = ["x", "y", "yaw", "w1", "w2", "w3", "s1", "s2"];
    let mut defs = vec![
        "d0 = yaw.cos() * dot(x) + yaw.sin() * dot(y)".to_string(),
        "d1 = -yaw.sin() * dot(x) + yaw.cos() * dot(y)".to_string(),
    ];
    for i in 2..definitions {
        let q = coordinates[i % coordinates.len()];
        let (a, b) = (i - 1, i - 2);
        defs.push(match i % 4 {
            0 => format!("d{i} = c{} * d{a} + {q}.sin() * d{b}", i % 3),
            1 => format!("d{i} = d{a} * {q}.cos() - c{} * d{b}", i % 3),
            2 => format!("d{i} = (d{a} - d{b}) / (1.0 + {q}.powi(2))"),
            _ => format!("d{i} = d{a} + dot({q}) * d{b} / (2.0 + d{b}.powi(2))"),
        });
    }
    let last = definitions - 1;
    let forces: Vec<String> = (0..coordinates.len())
        .map(|j| format!("d{} - k * dot({})", last - j, coordinates[j]))
        .collect();
    format!(
        "/// A model with {definitions} definitions (see `fixtures::definition_heavy`).\n\
         pub struct {name} {{\n\
         coordinates: [{}],\n\
         parameters: [c0, c1, c2, k],\n\
         mass: diag[1.0, 1.0, 0.5, 0.1, 0.1, 0.1, 2.0, 2.0],\n\
         definitions: [{}],\n\
         forces: [{}],\n\
         constraints: [-yaw.sin() * dot(x) + yaw.cos() * dot(y) == 0.0, s1 - s2 == 0.1 * d{}],\n\
         }}",
        coordinates.join(", "),
        defs.join(", "),
        forces.join(", "),
        (definitions / 50).max(2),
    )
}

/// The Franka Emika Panda's seven links, as published: the kinematics of
/// Franka's documentation (modified Denavit–Hartenberg: `d₁ = 0.333`,
/// `d₃ = 0.316`, `a₄ = 0.0825`, `a₅ = −0.0825`, `d₅ = 0.384`, `a₇ = 0.088`,
/// the joint frames turned by ±π/2 about x), and the inertial parameters
/// identified by Ledezma & Haddadin (mass; first moment `m c` in the joint
/// frame; inertia about the centre of mass `Ixx, Ixy, Ixz, Iyy, Iyz, Izz`).
/// Each row: joint origin `xyz`, roll in quarter turns (π/2 each), mass,
/// `m c`, inertia.
#[allow(clippy::type_complexity)]
pub const PANDA: [([&str; 3], i32, &str, [&str; 3], [&str; 6]); 7] = [
    (
        ["0.0", "0.0", "0.333"],
        0,
        "4.9707",
        ["0.0193", "0.0103", "-0.4654"],
        ["0.7470", "-0.0002", "0.0086", "0.7503", "0.0201", "0.0092"],
    ),
    (
        ["0.0", "0.0", "0.0"],
        -1,
        "0.6469",
        ["-0.0020", "-0.0186", "0.0023"],
        ["0.0085", "-0.0040", "0.0103", "0.0281", "0.0008", "0.0265"],
    ),
    (
        ["0.0", "-0.316", "0.0"],
        1,
        "3.2286",
        ["0.0888", "0.1267", "-0.2147"],
        [
            "0.0565", "-0.0082", "-0.0055", "0.0529", "-0.0044", "0.0182",
        ],
    ),
    (
        ["0.0825", "0.0", "0.0"],
        1,
        "3.5879",
        ["-0.1908", "0.3746", "0.0985"],
        ["0.0677", "0.0277", "0.0039", "0.0324", "-0.0016", "0.0776"],
    ),
    (
        ["-0.0825", "0.384", "0.0"],
        -1,
        "1.2259",
        ["-0.0147", "0.0503", "-0.0471"],
        ["0.0394", "-0.0015", "-0.0046", "0.0315", "0.0022", "0.0109"],
    ),
    (
        ["0.0", "0.0", "0.0"],
        1,
        "1.6666",
        ["0.1002", "-0.0235", "-0.0175"],
        ["0.0025", "0.0015", "-0.0001", "0.0106", "0.0001", "0.0118"],
    ),
    (
        ["0.088", "0.0", "0.0"],
        1,
        "1.4655",
        ["0.0004", "-0.0031", "0.1453"],
        ["0.0308", "0.0004", "-0.0007", "0.0284", "-0.0005", "0.0067"],
    ),
];

/// The first `joints` links of the Panda ([`PANDA`]) as a `bodies` section,
/// with a torque input per joint (`tau1`, …) and gravity along −z.
pub fn panda(name: &str, joints: usize) -> String {
    let bodies = panda_links("", "world", joints, None);
    let inputs: Vec<String> = (1..=joints).map(|k| format!("tau{k}")).collect();
    format!(
        "    /// The first {joints} links of the Franka Emika Panda, from published parameters.\n    \
         pub struct {name} {{\n        inputs: [{inputs}],\n        gravity: [0.0, 0.0, -9.81],\n        \
         bodies: [\n{bodies}        ],\n        forces: [{inputs}],\n    }}",
        inputs = inputs.join(", "),
    )
}

/// Two arms of the Panda's first `joints` links ([`PANDA`]), `left` and
/// `right`, on a torso turning about the vertical (`waist`, 20 kg, 0.4 m
/// tall, the arms' bases 0.25 m to either side): a branched tree, whose
/// `M` couples the arms only through the waist, so it has structural
/// zeros. Gravity along −z, no inputs.
pub fn two_arms(name: &str, joints: usize) -> String {
    let mut bodies = String::from(
        "        torso {\n            joint: revolute(waist, [0.0, 0.0, 1.0]),\n            \
         mass: 20.0,\n            com: [0.0, 0.0, 0.2],\n            inertia: diag[0.4, 0.3, 0.2],\n        },\n",
    );
    bodies.push_str(&panda_links(
        "left_",
        "torso",
        joints,
        Some("0.0, 0.25, 0.4"),
    ));
    bodies.push_str(&panda_links(
        "right_",
        "torso",
        joints,
        Some("0.0, -0.25, 0.4"),
    ));
    format!(
        "    /// Two arms of {joints} Panda links on a turning torso.\n    \
         pub struct {name} {{\n        gravity: [0.0, 0.0, -9.81],\n        \
         bodies: [\n{bodies}        ],\n    }}"
    )
}

/// The Panda's first `joints` links as `bodies` entries, named
/// `{prefix}link{k}` with coordinates `{prefix}q{k}`, the first hanging
/// from `parent` (at `base`, where given, instead of the table's origin).
fn panda_links(prefix: &str, parent: &str, joints: usize, base: Option<&str>) -> String {
    let mut bodies = String::new();
    for (i, (xyz, roll, mass, first, inertia)) in PANDA.iter().take(joints).enumerate() {
        let roll = f64::from(*roll);
        let (parent, xyz) = match (i, base) {
            (0, Some(base)) => (parent.to_string(), base.to_string()),
            (0, None) => (parent.to_string(), xyz.join(", ")),
            _ => (format!("{prefix}link{i}"), xyz.join(", ")),
        };
        let com = first.map(|c| format!("{c} / {mass}")).join(", ");
        let [xx, xy, xz, yy, yz, zz] = inertia;
        bodies.push_str(&format!(
            "        {prefix}link{k} {{\n            parent: {parent},\n            joint: revolute({prefix}q{k}, [0.0, 0.0, 1.0]),\n            \
             xyz: [{xyz}],\n            rpy: [{roll} * PI / 2.0, 0.0, 0.0],\n            mass: {mass},\n            com: [{com}],\n            \
             inertia: [[{xx}, {xy}, {xz}], [{xy}, {yy}, {yz}], [{xz}, {yz}, {zz}]],\n        }},\n",
            k = i + 1,
        ));
    }
    bodies
}

/// The quadruped of the repository's `examples/support/quadruped.rs` (a
/// floating base, twelve joints, four feet fixed: 19 coordinates, 13 rows)
/// as `constrained_system!` input, read from that file in the workspace:
/// the file writes the system inside a `macro_rules!` (for the tests' twin
/// with a fifth row and the balance example's frames), and this is its
/// plain instance, `Quadruped`. `None` outside the workspace (the file is
/// not packaged).
pub fn quadruped() -> Option<String> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/support/quadruped.rs"
    );
    let text = std::fs::read_to_string(path)
        .ok()?
        .replace("$(#[$attr])*", "")
        .replace("$($extra)*", "")
        .replace("$(frames: [$($frame)*],)?", "")
        .replace("$name", "Quadruped");
    let start = text.find("constrained_system! {")? + "constrained_system!".len();
    let body = &text[start..];
    let open = body.find('{')?;
    let mut depth = 0usize;
    for (i, c) in body.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(body[open + 1..i].to_string());
                }
            }
            _ => {}
        }
    }
    None
}
