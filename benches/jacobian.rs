//! The Jacobian of `q̈` (`acceleration_jacobian`) against central
//! differences and dual numbers. A binary of its own, as the projections':
//! in the acceleration binary its code changed how the compiler inlined
//! Appell's `acceleration` (1.33× the hand-written eq. 32 instead of 1.0×).

use constrained_chains::*;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

const G: f64 = 9.81;

/// The Jacobian of q̈ against what a user would do instead:
/// central differences (2·(2N + m) evaluations of `acceleration`) and dual
/// numbers (`num_dual::Dual64` as the scalar, one evaluation per column),
/// with one `acceleration` for scale. Cart-pole (generalized form, M(q),
/// one input) and the 8- and 32-link chains.
macro_rules! bench_jacobian {
    ($group:expr, $label:literal, $ty:ident, $make:expr, $make_dual:expr, $n:literal, $q:expr, $qd:expr) => {{
        let system: $ty<f64> = $make;
        let dual: $ty<num_dual::Dual64> = $make_dual;
        let (q, qd) = ($q, $qd);
        $group.bench_function(concat!($label, "/acceleration"), |b| {
            b.iter(|| system.acceleration(black_box(&q), black_box(&qd), black_box(0.0)))
        });
        // Each routine ends in `black_box(&j)`: the Jacobian is computed and
        // kept, but not moved (criterion copies a returned value, and copies
        // of a 32 KiB matrix would dominate the 32-link chain's timing).
        $group.bench_function(concat!($label, "/generated"), |b| {
            b.iter(|| {
                let j = system.acceleration_jacobian(black_box(&q), black_box(&qd), black_box(0.0));
                black_box(&j);
            })
        });
        $group.bench_function(concat!($label, "/central_differences"), |b| {
            b.iter(|| {
                let acc = |q: &constrained::nalgebra::SVector<f64, $n>,
                           qd: &constrained::nalgebra::SVector<f64, $n>| {
                    constrained::ConstrainedSystem::acceleration(
                        &system,
                        &constrained::State::new(0.0, *q, *qd),
                    )
                    .unwrap_or_else(|_| constrained::nalgebra::SVector::zeros())
                };
                let mut j = constrained::nalgebra::SMatrix::<f64, $n, { 2 * $n }>::zeros();
                for c in 0..$n {
                    let h = 1e-6;
                    let (mut p, mut m) = (q, q);
                    p[c] += h;
                    m[c] -= h;
                    j.set_column(c, &((acc(&p, &qd) - acc(&m, &qd)) / (2.0 * h)));
                    let (mut p, mut m) = (qd, qd);
                    p[c] += h;
                    m[c] -= h;
                    j.set_column($n + c, &((acc(&q, &p) - acc(&q, &m)) / (2.0 * h)));
                }
                black_box(&j);
            })
        });
        $group.bench_function(concat!($label, "/dual_numbers"), |b| {
            b.iter(|| {
                use num_dual::Dual64;
                let mut j = constrained::nalgebra::SMatrix::<f64, $n, { 2 * $n }>::zeros();
                for c in 0..2 * $n {
                    let qq = constrained::nalgebra::SVector::<Dual64, $n>::from_fn(|i, _| {
                        if i == c {
                            Dual64::new(q[i], 1.0)
                        } else {
                            Dual64::from(q[i])
                        }
                    });
                    let qqd = constrained::nalgebra::SVector::<Dual64, $n>::from_fn(|i, _| {
                        if i + $n == c {
                            Dual64::new(qd[i], 1.0)
                        } else {
                            Dual64::from(qd[i])
                        }
                    });
                    let a = constrained::ConstrainedSystem::acceleration(
                        &dual,
                        &constrained::State::new(Dual64::from(0.0), qq, qqd),
                    )
                    .unwrap_or_else(|_| constrained::nalgebra::SVector::zeros());
                    for i in 0..$n {
                        j[(i, c)] = a[i].eps;
                    }
                }
                black_box(&j);
            })
        });
    }};
}

fn jacobian(c: &mut Criterion) {
    use constrained::models::CartPole;
    use num_dual::Dual64;
    let mut group = c.benchmark_group("jacobian");
    let d = |x: f64| Dual64::from(x);
    bench_jacobian!(
        group,
        "cart_pole",
        CartPole,
        CartPole::new(1.0, 0.3, 0.8, G, 0.5),
        CartPole::new(d(1.0), d(0.3), d(0.8), d(G), d(0.5)),
        2,
        constrained::nalgebra::Vector2::new(0.2, 2.9),
        constrained::nalgebra::Vector2::new(-0.3, 0.4)
    );
    let (q, qd) = constrained_chains::benchmark_state::<16>();
    bench_jacobian!(
        group,
        "chain_8",
        Chain8,
        Chain8::new(G),
        Chain8::new(d(G)),
        16,
        q,
        qd
    );
    let (q, qd) = constrained_chains::benchmark_state::<64>();
    bench_jacobian!(
        group,
        "chain_32",
        Chain32,
        Chain32::new(G),
        Chain32::new(d(G)),
        64,
        q,
        qd
    );
    group.finish();
}

criterion_group!(benches, jacobian);
criterion_main!(benches);
