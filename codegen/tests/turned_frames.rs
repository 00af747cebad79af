//! What a joint frame turned by a constant rotation that mixes axes (a
//! URDF `rpy` that is not a multiple of a right angle, as the G1's
//! shoulders and hips have) costs in `M(q)` and `τ`: rotating the
//! composite inertia once and each force or motion vector that crosses the
//! frame once, not more: the sums on either side of such a rotation are
//! held, so that its constants are not distributed into every term of the
//! sums it reads and again into the cross products that read it.

use constrained_codegen::tools::op_count;
use constrained_codegen::{expand_with, Options};

/// An eight-joint chain of full inertias off their origins, its axes
/// cycling through z, y, x, y; joint `turned` (1-based) placed with `rpy`.
/// Each joint sits on the one axis that is neither its own nor its
/// parent's, where sliding frames along their axes (the dynamics' frames
/// are, where that empties a translation) finds nothing to empty: the
/// chain with a turned frame and the one without differ in the turn only.
fn chain(turned: usize, rpy: [f64; 3]) -> String {
    chain_of(8, |k| (k == turned).then_some(rpy))
}

/// [`chain`] of `n` joints, joint `k` (1-based) placed with `rpy(k)`
/// where that is some.
fn chain_of(n: usize, rpy: impl Fn(usize) -> Option<[f64; 3]>) -> String {
    let axis = |k: usize| [2, 1, 0, 1][(k - 1) % 4];
    // `value` along coordinate axis `c`, as the DSL writes a vector.
    let along = |c: usize, value: f64| {
        let mut p = [0.0; 3];
        p[c] = value;
        format!("[{:?}, {:?}, {:?}]", p[0], p[1], p[2])
    };
    let xyz = |k: usize| {
        let own = axis(k);
        let parent = if k == 1 { own } else { axis(k - 1) };
        let free = (0..3).find(|&c| c != own && c != parent).unwrap_or(0);
        along(free, 0.2)
    };
    let inputs: Vec<String> = (1..=n).map(|k| format!("u{k}")).collect();
    let mut bodies = String::new();
    for k in 1..=n {
        let parent = if k == 1 {
            String::new()
        } else {
            format!("parent: l{},", k - 1)
        };
        let turn = match rpy(k) {
            Some(r) => format!("rpy: [{:?}, {:?}, {:?}],", r[0], r[1], r[2]),
            None => String::new(),
        };
        bodies.push_str(&format!(
            "l{k} {{ {parent} joint: revolute(q{k}, {axis}), xyz: {xyz}, {turn}
                mass: 1.{k}, com: [0.01, 0.02, -0.03],
                inertia: [[0.01, 0.001, 0.002], [0.001, 0.02, 0.003], [0.002, 0.003, 0.03]] }},",
            axis = along(axis(k), 1.0),
            xyz = xyz(k),
        ));
    }
    format!(
        "pub struct Chain {{ inputs: [{i}], gravity: [0.0, 0.0, -9.81], bodies: [{bodies}], forces: [{i}], }}",
        i = inputs.join(", ")
    )
}

/// The operations of `M(q)` and of `τ` of the chain.
fn costs(source: &str) -> (usize, usize) {
    let tokens: proc_macro2::TokenStream = source.parse().expect("the chain is tokens");
    let expanded = expand_with(tokens, Options { jacobians: false }).expect("the chain expands");
    let file: syn::File = syn::parse2(expanded).expect("the expansion is Rust");
    let count = |name| op_count::method(&file, name).map_or(0, |o| o.total());
    (count("mass_matrix"), count("inverse_dynamics"))
}

#[test]
fn a_turned_joint_frame_costs_its_rotations_once() {
    // Nearly a turn about x, as the G1's left shoulder is placed.
    let rpy = [0.27931, 5.4949e-05, -0.00019159];
    let (plain_m, plain_tau) = costs(&chain(0, rpy));
    for turned in [2, 5, 8] {
        let (m, tau) = costs(&chain(turned, rpy));
        // The columns of joints `turned..=8` cross the frame: in `M` each
        // one's force (two 3-vectors, 15 operations each through a dense
        // rotation), and the subtree's composite inertia once (`R Ī Rᵀ`,
        // its first moment and the shift: under 120). In `τ` the velocity
        // and the acceleration cross it outward, the force inward (six
        // 3-vectors: 90), once.
        let crossing = 8 - turned + 1;
        let m_bound = 30 * crossing + 120;
        assert!(
            m <= plain_m + m_bound,
            "joint {turned} turned: M costs {m} operations, {plain_m} unturned \
             (at most {m_bound} more expected)"
        );
        assert!(
            tau <= plain_tau + 90,
            "joint {turned} turned: τ costs {tau} operations, {plain_tau} unturned"
        );
    }
}

/// The derivation of a system given as tokens.
fn derivation(source: &str) -> String {
    let tokens: proc_macro2::TokenStream = source.parse().expect("the chain is tokens");
    let eq = constrained_codegen::analyse_with(tokens, Options { jacobians: false })
        .expect("the chain is analysed");
    constrained_codegen::emit::derivation::text(&eq, &eq.partition)
}

/// Every frame of a 24-joint chain turned as an exported URDF turns them
/// (`1.5708`, not π/2, and angles about two axes at once): `M` is formed
/// in world axes, which costs fewer operations there, the columns being
/// carried through many dense rotations the other way
/// (`bodies::world_mass`; on twelve joints the bodies' own axes still
/// win), and the derivation says so. With one frame
/// turned the bodies' own axes stay the cheaper, and the derivation
/// states the recursion through the joints.
#[test]
// 1.5708 is the exporter's number, 3.7e-6 rad from π/2: not the constant.
#[allow(clippy::approx_constant)]
fn mass_in_world_axes_where_every_frame_is_turned() {
    let exported =
        |k: usize| Some([[1.5708, 0.0, 0.3], [0.0, -0.7, 1.1], [0.4, 1.5708, 0.0]][k % 3]);
    let world = "M in world axes";
    let through_joints = "Mⱼᵢ = Sⱼᵀ jX_iᵀ … Iᶜᵢ Sᵢ for each ancestor j of i.";
    let text = derivation(&chain_of(24, exported));
    assert!(
        text.contains(world) && !text.contains(through_joints),
        "{text}"
    );
    let rpy = [0.27931, 5.4949e-05, -0.00019159];
    let text = derivation(&chain(5, rpy));
    assert!(
        text.contains(through_joints) && !text.contains(world),
        "{text}"
    );
}
