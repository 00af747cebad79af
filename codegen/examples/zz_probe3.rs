use constrained_codegen::tools::fixtures::joint_angle_pendulum;
fn main() {
    let links: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let reps: usize = std::env::args().nth(2).map_or(1, |r| r.parse().unwrap());
    let tokens: proc_macro2::TokenStream = joint_angle_pendulum("Pendulum", links).parse().unwrap();
    let t = std::time::Instant::now();
    for _ in 0..reps { let _ = constrained_codegen::expand(tokens.clone()).unwrap(); }
    println!("{:.4}", t.elapsed().as_secs_f64() / reps as f64);
}
