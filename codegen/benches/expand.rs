//! How long `constrained_system!` takes to expand, against the size of the
//! system: the planar N-link chain (2N coordinates, N constraints).

use constrained_codegen::{expand, fixtures::planar_chain};
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

criterion_group!(benches, expansion);
criterion_main!(benches);
