//! One RK4 step of the planar N-link chain with Baumgarte stabilization
//! (rate 10/s), from the same consistent state as the plain step
//! (`benches/acceleration.rs`) and the projected one
//! (`benches/projection.rs`). A binary of its own, like the projection's:
//! in the projection's binary it changed how the projected step was
//! inlined (N = 4: 248 ns alone, 413 ns beside it).

#[macro_use]
mod steps;

use constrained_chains::*;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

const G: f64 = 9.81;

/// RK4 with Baumgarte's correction at rate 10/s.
fn stabilized() -> constrained::Rk4<f64> {
    constrained::Rk4::new(1e-3).with_stabilization(constrained::Stabilization::baumgarte(10.0))
}

fn baumgarte(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain_rk4_step_baumgarte");
    bench_rk4_step!(group, Chain1, 1, 2, stabilized());
    bench_rk4_step!(group, Chain2, 2, 4, stabilized());
    bench_rk4_step!(group, Chain4, 4, 8, stabilized());
    bench_rk4_step!(group, Chain8, 8, 16, stabilized());
    bench_rk4_step!(group, Chain16, 16, 32, stabilized());
    bench_rk4_step!(group, Chain32, 32, 64, stabilized());
    group.finish();
}

criterion_group!(benches, baumgarte);
criterion_main!(benches);
