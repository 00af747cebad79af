use constrained_codegen::{expand_with, tools::op_count, Options};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let src = std::fs::read_to_string(path).unwrap();
    let tokens: proc_macro2::TokenStream = src.parse().unwrap();
    let t = std::time::Instant::now();
    let expanded = expand_with(
        tokens,
        Options {
            jacobians: std::env::var("JAC").is_ok(),
        },
    )
    .unwrap();
    eprintln!("expansion {:?}", t.elapsed());
    let file: syn::File = syn::parse2(expanded).unwrap();
    if let Some(out) = std::env::args().nth(2) {
        std::fs::write(out, prettyplease::unparse(&file)).unwrap();
    }
    for m in [
        "gauss",
        "tangent_rhs",
        "acceleration_jacobian",
        "acceleration",
        "inverse_dynamics",
        "inverse_dynamics_jacobian",
        "mass_matrix",
        "left_sole_placement",
        "left_sole_jacobian",
        "left_sole_acceleration_bias",
        "center_of_mass",
        "center_of_mass_jacobian",
        "center_of_mass_and_jacobian",
        "center_of_mass_velocity",
        "centroidal_map",
        "centroidal_map_bias",
    ] {
        if let Some(o) = op_count::method(&file, m) {
            println!(
                "{m}: {} ({} mul {} add {} sub {} neg {} div {} fn)",
                o.total(),
                o.mul,
                o.add,
                o.sub,
                o.neg,
                o.div,
                o.functions
            );
        }
    }
}
