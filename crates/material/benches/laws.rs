//! Cost of one stress/tangent evaluation: analytic derivatives versus automatic differentiation.
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use tubemem_material::{energies, laws::AnssariBenamBucchi, AutoDiff, MembraneLaw};

fn bench(c: &mut Criterion) {
    let an = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let ad = AutoDiff::new(energies::AbbEnergy { kuhn: 30.0 }, 1.0).unwrap();
    let cs = [1.69, 1.1025, 0.05];
    c.bench_function("abb_stress_tangent_analytic", |b| {
        b.iter(|| an.stress_tangent(black_box(cs)).unwrap())
    });
    c.bench_function("abb_stress_tangent_autodiff", |b| {
        b.iter(|| ad.stress_tangent(black_box(cs)).unwrap())
    });
    c.bench_function("abb_derivatives_autodiff_hand", |b| {
        b.iter(|| {
            ad.derivatives_ab_hand(black_box(2.1), black_box(0.9))
                .unwrap()
        })
    });
    c.bench_function("abb_derivatives_autodiff_numdual", |b| {
        b.iter(|| {
            ad.derivatives_ab_num_dual(black_box(2.1), black_box(0.9))
                .unwrap()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
