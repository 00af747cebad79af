//! The generated chains against independent truths: the Cartesian q̈ of the
//! sympy/numpy reference data (`tests/data/reference_vectors.json`, N = 1…4)
//! and the angle accelerations θ̈ that sympy's LagrangesMethod derived in
//! minimal coordinates; and, for every length, A q̈ = b at consistent states.

use constrained::nalgebra::SVector;
use constrained_chains::*;

fn reference() -> serde_json::Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/reference_vectors.json"
    );
    let text = std::fs::read_to_string(path).expect("reference data is in the repository");
    serde_json::from_str(&text).expect("valid JSON")
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// θ̈ from Cartesian q̈: θᵢ is measured from the downward vertical, so with
/// (dx, dy) = pᵢ − pᵢ₋₁ = L (sin θ, −cos θ), θ̈ = (ẍ cos θ + ÿ sin θ − …)/L;
/// exactly: d²/dt² atan2(dx, −dy).
fn angle_accelerations(q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let n = q.len() / 2;
    (0..n)
        .map(|i| {
            let prev = |v: &[f64], k: usize| if i == 0 { 0.0 } else { v[2 * (i - 1) + k] };
            let (dx, dy) = (q[2 * i] - prev(q, 0), q[2 * i + 1] - prev(q, 1));
            let (vx, vy) = (qd[2 * i] - prev(qd, 0), qd[2 * i + 1] - prev(qd, 1));
            let (ax, ay) = (qdd[2 * i] - prev(qdd, 0), qdd[2 * i + 1] - prev(qdd, 1));
            // θ = atan2(dx, −dy): θ̈ = (u·w' − w·u')' / r² terms, written out.
            let r2 = dx * dx + dy * dy;
            let num = -dy * vx + dx * vy; // r² θ̇
            let num_dot = -dy * ax + dx * ay; // d/dt (r² θ̇), the −vy·vx + vx·vy terms cancel
            let r2_dot = 2.0 * (dx * vx + dy * vy);
            (num_dot * r2 - num * r2_dot) / (r2 * r2)
        })
        .collect()
}

macro_rules! check_case {
    ($case:expr, $chain:ty, $n:literal) => {{
        let case = $case;
        let q = numbers(&case["q_cart[x1,y1,...]"]);
        let qd = numbers(&case["qd_cart"]);
        let expected = numbers(&case["xdd_cart_UK"]);
        let thdd = numbers(&case["thdd_lagrange"]);
        let system = <$chain>::new(9.81);
        let qv = SVector::<f64, $n>::from_column_slice(&q);
        let qdv = SVector::<f64, $n>::from_column_slice(&qd);
        let qdd = system.acceleration(&qv, &qdv, 0.0);
        for i in 0..$n {
            assert!(
                (qdd[i] - expected[i]).abs() < 1e-11,
                "N = {}: q̈ = {qdd} vs {expected:?}",
                $n / 2
            );
        }
        let angles = angle_accelerations(&q, &qd, qdd.as_slice());
        for (a, b) in angles.iter().zip(&thdd) {
            assert!(
                (a - b).abs() < 1e-10,
                "N = {}: θ̈ = {angles:?} vs Lagrange {thdd:?}",
                $n / 2
            );
        }
    }};
}

#[test]
fn chains_match_sympy_reference_data() {
    let data = reference();
    let cases = data["chain"]["cases"].as_array().expect("cases");
    assert_eq!(cases.len(), 4);
    for case in cases {
        match case["N"].as_u64() {
            Some(1) => check_case!(case, Chain1, 2),
            Some(2) => check_case!(case, Chain2, 4),
            Some(3) => check_case!(case, Chain3, 6),
            Some(4) => check_case!(case, Chain4, 8),
            other => panic!("unexpected chain length {other:?}"),
        }
    }
}

macro_rules! constraint_equations_hold {
    ($test:ident, $chain:ty, $links:literal, $m:literal) => {
        #[test]
        fn $test() {
            let angles: Vec<f64> = (0..$links).map(|i| (0.7 * i as f64).sin() * 1.3).collect();
            let rates: Vec<f64> = (0..$links).map(|i| (1.1 * i as f64 + 0.4).cos()).collect();
            let (q, qd) = constrained_chains::consistent_state::<$m>(&angles, &rates);
            let system = <$chain>::new(9.81);
            assert!(system.constraint_residual(&q, &qd, 0.0).amax() < 1e-12);
            let qdd = system.acceleration(&q, &qd, 0.0);
            let (a, b) = system.constraint_matrices(&q, &qd, 0.0);
            let scale = (a.abs() * qdd.abs()).norm() + b.norm();
            assert!(
                (a * qdd - b).norm() < 1e-12 * scale,
                "A q̈ − b = {}",
                (a * qdd - b).norm()
            );
            let mp = system
                .acceleration_moore_penrose(&q, &qd, 0.0)
                .expect("finite");
            assert!(
                (mp - qdd).norm() < 1e-10 * qdd.norm(),
                "Moore–Penrose differs by {}",
                (mp - qdd).norm()
            );
        }
    };
}

constraint_equations_hold!(chain_8_constraint_equations, Chain8, 8, 16);
constraint_equations_hold!(chain_16_constraint_equations, Chain16, 16, 32);
constraint_equations_hold!(chain_32_constraint_equations, Chain32, 32, 64);

macro_rules! gibbs_appell_agrees {
    ($test:ident, $chain:ty, $links:literal, $m:literal) => {
        /// The explicit Gibbs–Appell form equals the generalized-inverse one
        /// along a sweep of 100 configurations. Keeping the compile-time
        /// partition wherever it merely had full rank gave up to 2.8e-12
        /// (N = 8) and 6.7e-9 (N = 32) here: links near horizontal make the
        /// columns of their y small. Re-pivoting where the partition is
        /// poorly conditioned keeps both below 7e-16.
        #[test]
        fn $test() {
            let system = <$chain>::new(9.81);
            for step in 0..100 {
                let phase = 0.1 * step as f64;
                let angles: Vec<f64> = (0..$links)
                    .map(|i| 2.0 * (0.7 * i as f64 + phase).sin())
                    .collect();
                let rates: Vec<f64> = (0..$links).map(|i| (1.1 * i as f64).cos()).collect();
                let (q, qd) = constrained_chains::consistent_state::<$m>(&angles, &rates);
                let qdd = system.acceleration(&q, &qd, 0.0);
                let ga = system
                    .acceleration_gibbs_appell(&q, &qd, 0.0)
                    .expect("A has full rank");
                let error = (ga - qdd).norm() / qdd.norm();
                assert!(
                    error < 1e-13,
                    "phase {phase}: relative difference {error:e}"
                );
            }
        }
    };
}

gibbs_appell_agrees!(chain_8_gibbs_appell, Chain8, 8, 16);
gibbs_appell_agrees!(chain_32_gibbs_appell, Chain32, 32, 64);
