//! Cost of the element kernels on one quad at a finite-strain state (ABB 𝒩 = 30 with the
//! tension-field relaxation, as the runs use): membrane residual + 12×12 tangent, volume with
//! gradient + Hessian, and penalty contact against one penetrated plane; and the membrane
//! kernel with laws written as text against the same laws built in (Gent as an energy of I1,
//! a two-term Ogden law as w(l)), for the cost of a user's law in an FE run.
//! `cargo bench -p tubemem-fem --bench kernels`
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use tubemem_fem::contact::{Contact, Plane};
use tubemem_fem::element::{membrane_kernel, Matrix12, Vector12};
use tubemem_fem::geometry::{RefElement, Vec3};
use tubemem_material::{MaterialSpec, Wrinkling};
use tubemem_mesh::volume::volume_kernel;

fn bench(c: &mut Criterion) {
    let law = MaterialSpec::Abb {
        shear_modulus: 1.0,
        kuhn: 30.0,
    }
    .build_with(Wrinkling::Relaxed)
    .unwrap();
    let x0 = [
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.0],
        [1.1, 1.0, 0.1],
        [0.0, 0.9, 0.0],
    ];
    let x = x0.map(|p| [1.3 * p[0] + 0.1 * p[1], 1.15 * p[1], p[2] + 0.2 * p[0]]);
    let re = RefElement::new(0, [0, 1, 2, 3], &x0).unwrap();
    let x = x.map(Vec3::from);
    let mut r = Vector12::zeros();
    let mut k = Matrix12::zeros();
    c.bench_function("membrane_kernel_with_tangent", |b| {
        b.iter(|| {
            r = Vector12::zeros();
            k = Matrix12::zeros();
            membrane_kernel(law.as_ref(), &re, black_box(&x), &mut r, Some(&mut k)).unwrap()
        })
    });
    let spec = |json: &str| {
        serde_json::from_str::<MaterialSpec>(json)
            .unwrap()
            .build_with(Wrinkling::Relaxed)
            .unwrap()
    };
    for (name, json) in [
        (
            "gent_built_in",
            r#"{"model": "gent", "shear_modulus": 1.0, "jm": 50}"#,
        ),
        (
            "gent_as_text",
            r#"{"model": "invariants", "energy": "-(jm / 2) * ln(1 - (I1 - 3) / jm)", "parameters": {"jm": 50}, "shear_modulus": 1.0}"#,
        ),
        (
            "ogden_built_in",
            r#"{"model": "ogden", "mu": [1.3, 0.05], "alpha": [1.3, 5.0]}"#,
        ),
        (
            "ogden_as_text",
            r#"{"model": "principal", "energy": "m1/a1 * (l^a1 - 1) + m2/a2 * (l^a2 - 1)", "parameters": {"m1": 1.3, "a1": 1.3, "m2": 0.05, "a2": 5.0}, "shear_modulus": 1.0}"#,
        ),
    ] {
        let law = spec(json);
        c.bench_function(&format!("membrane_kernel_{name}"), |b| {
            b.iter(|| {
                r = Vector12::zeros();
                k = Matrix12::zeros();
                membrane_kernel(law.as_ref(), &re, black_box(&x), &mut r, Some(&mut k)).unwrap()
            })
        });
    }
    let mut g = Vector12::zeros();
    let mut h = Matrix12::zeros();
    c.bench_function("volume_kernel_with_hessian", |b| {
        b.iter(|| {
            g = Vector12::zeros();
            h = Matrix12::zeros();
            volume_kernel(black_box(&x), Some(&mut g), Some(&mut h))
        })
    });
    let contact = Contact {
        planes: vec![Plane {
            normal: [0.0, -1.0, 0.0],
            offset: -1.0,
        }],
        penalty: 1e3,
        enforcement: tubemem_fem::contact::Enforcement::Penalty,
        points: Default::default(),
    };
    c.bench_function("contact_kernel_with_tangent", |b| {
        b.iter(|| {
            r = Vector12::zeros();
            k = Matrix12::zeros();
            contact.kernel(&re, black_box(&x), &[], &mut r, Some(&mut k))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
