//! Projection onto the constraints (`Stabilization::projection`), through
//! the generated factorizations: one RK4 step of the planar N-link chain
//! with projection after it, and the projection alone from a state knocked
//! off the constraints. A binary of its own: sharing one with the plain RK4
//! benchmarks changed how the compiler inlined those (their integrator then
//! had two kinds of caller) and slowed them by up to half.

#[macro_use]
mod steps;

use constrained_chains::*;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

const G: f64 = 9.81;

/// One RK4 step with projection onto the constraints after it, and the
/// projection alone from a state knocked 1e-6 off the constraints (in q and
/// q̇, so that both Newton solves run).
macro_rules! bench_projection {
    ($c:expr, $chain:ty, $links:literal, $m:literal) => {{
        let mut step = $c.benchmark_group("chain_rk4_step_projection");
        bench_rk4_step!(
            step,
            $chain,
            $links,
            $m,
            constrained::Rk4::new(1e-3)
                .with_stabilization(constrained::Stabilization::projection(1e-12))
        );
        step.finish();
        let system = <$chain>::new(G);
        let (q, qd) = constrained_chains::benchmark_state::<$m>();
        let off = constrained::nalgebra::SVector::<f64, $m>::from_fn(|i, _| {
            1e-6 * (1.0 + i as f64).sin()
        });
        let mut alone = $c.benchmark_group("chain_projection");
        alone.bench_with_input(BenchmarkId::from_parameter($links), &$links, |b, _| {
            b.iter(|| {
                let mut s = constrained::State::new(0.0, q + off, qd + off);
                constrained::stabilize::project(&system, &mut s, 1e-12, 20).expect("projects");
                black_box(s)
            })
        });
        alone.finish();
    }};
}

fn projection(c: &mut Criterion) {
    bench_projection!(c, Chain1, 1, 2);
    bench_projection!(c, Chain2, 2, 4);
    bench_projection!(c, Chain4, 4, 8);
    bench_projection!(c, Chain8, 8, 16);
    bench_projection!(c, Chain16, 16, 32);
    bench_projection!(c, Chain32, 32, 64);
}

criterion_group!(benches, projection);
criterion_main!(benches);
