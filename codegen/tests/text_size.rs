//! The texts a system carries (`DERIVATION`, `SYMBOLIC`) and its generated
//! code grow linearly with the expression DAG, not with the expression
//! trees, which for Lagrange's equations of an N-link pendulum grow
//! exponentially (written out in full, N = 16 gave 63 MB).

use constrained_codegen::tools::fixtures::joint_angle_pendulum;
use constrained_codegen::{analyse, emit, emit::derivation};

#[test]
fn text_grows_linearly_with_the_dag() {
    for links in [4, 8, 12, 16] {
        let tokens = joint_angle_pendulum("Pendulum", links)
            .parse()
            .expect("tokens");
        let eq = analyse(tokens).expect("expands");
        let nodes = eq.system.graph.len();
        let derivation = derivation::text(&eq, &eq.partition).len();
        let expansion = emit::system(&eq).to_string().len();
        let (per_node_text, per_node_all) = (derivation / nodes, expansion / nodes);
        println!(
            "N = {links}: {nodes} nodes, DERIVATION {derivation} bytes ({per_node_text}/node), \
             expansion {expansion} bytes ({per_node_all}/node)"
        );
        assert!(
            per_node_text < 40,
            "N = {links}: {per_node_text} bytes of derivation per node"
        );
        assert!(
            per_node_all < 150,
            "N = {links}: {per_node_all} bytes of expansion per node"
        );
    }
}
