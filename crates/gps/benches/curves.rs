//! Issue target: a 10,000-point GPS inflation curve plus the two flattening curves of Fig. 7
//! (λs* = 6.0 to ρ = 3.0, GPS and PS, 1,000 points each) under 20 ms together.
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use tubemem_gps::{flattening_curve, inflation_curve, limits::limit_points, Hypothesis};
use tubemem_material::laws::AnssariBenamBucchi;

fn bench(c: &mut Criterion) {
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    c.bench_function("fig5_inflation_10000_plus_fig7_flattening_2x1000", |b| {
        b.iter(|| {
            let a = inflation_curve(&law, Hypothesis::Gps, 1.0, 7.5, black_box(10_000)).unwrap();
            let g = flattening_curve(&law, Hypothesis::Gps, 6.0, 3.0, black_box(1_000)).unwrap();
            let p = flattening_curve(&law, Hypothesis::Ps, 6.0, 3.0, black_box(1_000)).unwrap();
            (a.len(), g.len(), p.len())
        })
    });
    c.bench_function("gps_inflation_curve_10000", |b| {
        b.iter(|| inflation_curve(&law, Hypothesis::Gps, 1.0, 7.5, black_box(10_000)).unwrap())
    });
    c.bench_function("limit_points_and_maxwell_abb30", |b| {
        b.iter(|| limit_points(black_box(&law), Hypothesis::Gps).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
