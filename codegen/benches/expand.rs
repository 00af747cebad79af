//! How long `constrained_system!` takes to expand, against the size of the
//! system: the planar N-link chain (2N coordinates, N constraints).

use constrained_codegen::expand;
use constrained_codegen::tools::fixtures::{joint_angle_pendulum, planar_chain};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use proc_macro2::TokenStream;
use std::hint::black_box;

fn expansion(c: &mut Criterion) {
    let mut group = c.benchmark_group("expand_planar_chain");
    group.sample_size(20);
    for links in [1usize, 2, 4, 8, 16, 32] {
        let tokens: TokenStream = planar_chain("Chain", links).parse().expect("valid tokens");
        group.bench_with_input(BenchmarkId::from_parameter(links), &tokens, |b, tokens| {
            b.iter(|| expand(black_box(tokens.clone())).expect("expands"))
        });
    }
    group.finish();
}

/// The N-link pendulum in joint angles from its energies: Lagrange's
/// equations derived at compile time (dense `M(q)`, O(N²) velocity
/// products in `F`). Compared with sympy's LagrangesMethod on the same
/// model by `benches/lagrange_sympy.py`.
fn expansion_from_energies(c: &mut Criterion) {
    let mut group = c.benchmark_group("expand_joint_angle_pendulum");
    group.sample_size(10);
    for links in [2usize, 4, 8, 16] {
        let tokens: TokenStream = joint_angle_pendulum("Pendulum", links)
            .parse()
            .expect("valid tokens");
        group.bench_with_input(BenchmarkId::from_parameter(links), &tokens, |b, tokens| {
            b.iter(|| expand(black_box(tokens.clone())).expect("expands"))
        });
    }
    group.finish();
}

criterion_group!(benches, expansion, expansion_from_energies);
criterion_main!(benches);
