//! Systems generated as DSL text, for benchmarks and tests that need a family
//! of sizes (the macro itself cannot loop over N).

use std::fmt::Write;

/// A planar N-link pendulum in Cartesian coordinates, as `constrained_system!`
/// input: point masses `mᵢ = 1 + 0.1 i` at the joints of rods
/// `Lᵢ = 1 + 0.05 i`, the first rod pivoting at the origin, gravity `g` along
/// −y. 2N coordinates, N position-level constraints. The masses and lengths
/// are those of `shared/data/reference_vectors.json` (`chain`).
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
