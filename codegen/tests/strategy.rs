//! The solve is decided once (`Equations::strategy`), and the generated
//! `gauss` and `DERIVATION` state the same one: for every strategy, on
//! models that take it, the sentence of `Strategy::describe` stands in
//! `gauss`'s documentation and in the derivation, and no other strategy's
//! does.

mod common;

use constrained_codegen::equations::strategy::Strategy;
use constrained_codegen::{analyse_with, expand, Options};
use std::collections::BTreeMap;

/// A top pinned at a point by a spherical joint from the world: the
/// velocity form's saddle-point system, with no legs.
const PINNED_TOP: &str = "
    pub struct PinnedTop {
        bodies: [
            top {
                joint: free(x, y, z, e0, e1, e2, e3),
                mass: 1.0,
                com: [0.0, 0.0, 0.3],
                inertia: diag[0.02, 0.02, 0.01],
            },
        ],
        constraints: [position(top, [0.0, 0.0, 0.0]) == [0.0, 0.0, 0.0]],
    }";

/// A planar walker: a base on a planar joint, four two-joint legs, every
/// foot held at its place. No quaternion, so no velocity form; each foot's
/// rows touch its own leg and the base: the saddle-point system.
fn planar_walker() -> String {
    let legs = [("a", 0.3), ("b", 0.1), ("c", -0.1), ("d", -0.3)];
    let bodies: String = legs
        .iter()
        .map(|(leg, x)| {
            format!(
                "{leg}_thigh {{ parent: base, joint: revolute({leg}_hip, [0.0, 0.0, 1.0]), \
                 xyz: [{x:?}, 0.0, 0.0], mass: 0.4, com: [0.0, -0.1, 0.0], \
                 inertia: diag[0.002, 0.002, 0.001] }},
                 {leg}_shank {{ parent: {leg}_thigh, joint: revolute({leg}_knee, [0.0, 0.0, 1.0]), \
                 xyz: [0.0, -0.2, 0.0], mass: 0.2, com: [0.0, -0.1, 0.0], \
                 inertia: diag[0.001, 0.001, 0.0005] }},"
            )
        })
        .collect();
    let feet: String = legs
        .iter()
        .map(|(leg, x)| {
            format!(
                "position({leg}_shank, [0.0, -0.2, 0.0]).x == {x:?}, \
                 position({leg}_shank, [0.0, -0.2, 0.0]).y == -0.4,"
            )
        })
        .collect();
    format!(
        "pub struct PlanarWalker {{
            gravity: [0.0, -9.81, 0.0],
            bodies: [
                base {{ joint: planar(x, y, th), mass: 3.0, com: [0.0, 0.0, 0.0], \
                        inertia: diag[0.05, 0.1, 0.05] }},
                {bodies}
            ],
            constraints: [{feet}],
        }}"
    )
}

fn strategy_of(name: &str, tokens: proc_macro2::TokenStream) -> Strategy {
    let eq = analyse_with(tokens.clone(), Options { jacobians: false })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let strategy = eq.strategy();
    let derivation = constrained_codegen::emit::derivation::text(&eq, &eq.partition);
    let expansion = expand(tokens)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .to_string();
    let gauss = expansion
        .find("fn gauss <")
        .map(|at| &expansion[..at])
        .and_then(|before| before.rfind("# [doc").map(|doc| &before[doc..]))
        .unwrap_or_else(|| panic!("{name}: a documented gauss"));
    for other in Strategy::ALL {
        // The expansion writes the doc as a string literal, escaped.
        let literal = proc_macro2::Literal::string(other.describe()).to_string();
        let words = literal.trim_matches('"');
        let stated = derivation.contains(&format!("acceleration's {}", other.describe()));
        assert_eq!(
            stated,
            other == strategy,
            "{name}: {other:?} in the derivation"
        );
        assert_eq!(
            gauss.contains(words),
            other == strategy,
            "{name}: {other:?} in gauss's doc: {gauss}"
        );
    }
    strategy
}

#[test]
fn every_strategy_is_stated_as_it_is_emitted() {
    let mut seen: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut models: Vec<(String, proc_macro2::TokenStream)> = common::model_invocations()
        .into_iter()
        .chain(common::example_invocations(&[
            "five_bar.rs",
            "support/damped_crane.rs",
            "support/panda.rs",
        ]))
        .map(|m| (m.name, m.tokens))
        .collect();
    models.push(("PinnedTop".into(), PINNED_TOP.parse().expect("tokens")));
    models.push((
        "PlanarWalker".into(),
        planar_walker().parse().expect("tokens"),
    ));
    if let Some(text) = constrained_codegen::tools::fixtures::quadruped() {
        models.push(("Quadruped".into(), text.parse().expect("tokens")));
    }
    for (name, tokens) in models {
        let strategy = strategy_of(&name, tokens);
        seen.entry(format!("{strategy:?}")).or_default().push(name);
    }
    for strategy in Strategy::ALL {
        assert!(
            seen.contains_key(&format!("{strategy:?}")),
            "no model takes {strategy:?}: {seen:?}"
        );
    }
}
