//! One RK4 step of the planar N-link chain with Baumgarte stabilization
//! (rate 10/s), from the same consistent state as the plain step
//! (`benches/acceleration.rs`) and the projected one
//! (`benches/projection.rs`). A binary of its own, like the projection's:
//! in the projection's binary it changed how the projected step was
//! inlined (N = 4: 248 ns alone, 413 ns beside it).

use constrained_chains::*;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

const G: f64 = 9.81;

macro_rules! bench_baumgarte {
    ($group:expr, $chain:ty, $links:literal, $m:literal) => {{
        let system = <$chain>::new(G);
        let (q, qd) = constrained_chains::benchmark_state::<$m>();
        let rk4 = constrained::Rk4::new(1e-3)
            .with_stabilization(constrained::Stabilization::baumgarte(10.0));
        $group.bench_with_input(BenchmarkId::from_parameter($links), &$links, |b, _| {
            b.iter(|| {
                let mut s = constrained::State::new(0.0, q, qd);
                rk4.advance(&system, &mut s, 1e-3).expect("one step");
                black_box(s)
            })
        });
    }};
}

fn baumgarte(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain_rk4_step_baumgarte");
    bench_baumgarte!(group, Chain1, 1, 2);
    bench_baumgarte!(group, Chain2, 2, 4);
    bench_baumgarte!(group, Chain4, 4, 8);
    bench_baumgarte!(group, Chain8, 8, 16);
    bench_baumgarte!(group, Chain16, 16, 32);
    bench_baumgarte!(group, Chain32, 32, 64);
    group.finish();
}

criterion_group!(benches, baumgarte);
criterion_main!(benches);
