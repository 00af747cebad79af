//! The RK4-step benchmark of the planar chains, shared by the binaries that
//! time plain (`acceleration.rs`), Baumgarte-stabilized (`baumgarte.rs`)
//! and projected (`projection.rs`) steps. They stay separate binaries (a
//! stabilized step beside another changed how the compiler inlined it);
//! only the source is shared.

/// One step of `$rk4` (an `Rk4`, plain or stabilized, h = 1 ms) of the
/// chain `$chain` with `$links` links (`$m` = 2·links coordinates), from
/// its benchmark state each time, as benchmark `$links` of `$group`.
macro_rules! bench_rk4_step {
    ($group:expr, $chain:ty, $links:literal, $m:literal, $rk4:expr) => {{
        let system = <$chain>::new(G);
        let (q, qd) = constrained_chains::benchmark_state::<$m>();
        let rk4 = $rk4;
        $group.bench_with_input(BenchmarkId::from_parameter($links), &$links, |b, _| {
            b.iter(|| {
                let mut s = constrained::State::new(0.0, q, qd);
                rk4.advance(&system, &mut s, 1e-3).expect("one step");
                black_box(s)
            })
        });
    }};
}
