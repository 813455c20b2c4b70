//! Carrying a state from a coarser mesh ([`Model::prolong`]) and stepping a stage from a
//! coarse run's states ([`crate::stepping::Guide`]): a translation carries over exactly, a
//! smooth field converges at the element's order, a node off the coarse surface is refused, a
//! state pressed flat on a plane stays on it, a carried inflation is the fine mesh's own
//! equilibrium after fewer Newton iterations, and a guided stage whose guide fails is cut back
//! and finished without it.

use crate::contact::Contact;
use crate::model::{Load, Model, State};
use crate::stepping::{run_stage_refitted, Guide, Stage, StepSettings};
use crate::FemError;
use tubemem_material::laws::AnssariBenamBucchi;
use tubemem_mesh::tube::capped_tube_fitted_of;
use tubemem_mesh::{ElementKind, Mesh, Symmetry};

/// A tube L/R = 8 of `around` elements around, as many along, around/8 cap rows, radius `r`.
fn tube(kind: ElementKind, around: usize, symmetry: Symmetry, r: f64) -> Mesh {
    capped_tube_fitted_of(kind, r, 8.0 * r, around, around, around / 8, symmetry, None).unwrap()
}

fn model(mesh: Mesh) -> Model {
    Model::new(mesh, Box::new(AnssariBenamBucchi::new(1.0, 30.0).unwrap())).unwrap()
}

/// A state of `m` with every node at `f`(reference position).
fn mapped(m: &Model, f: impl Fn([f64; 3]) -> [f64; 3]) -> State {
    let mut st = m.reference_state();
    st.x = m.mesh().nodes.iter().map(|&p| f(p)).collect();
    st
}

/// The largest coordinate difference of two position arrays.
fn distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max)
}

/// A translation is interpolated exactly by both elements (their shape functions sum to 1):
/// to round-off, 1e-14 R; the components a rigid-mode pin fixes stay at their reference values.
#[test]
fn a_translation_carries_over_exactly() {
    for kind in [ElementKind::Quad4, ElementKind::Quad9] {
        let coarse = model(tube(kind, 16, Symmetry::None, 1.0));
        let fine = model(tube(kind, 32, Symmetry::None, 1.0));
        let t = [0.3, -0.2, 0.7];
        let shift = |p: [f64; 3]| [p[0] + t[0], p[1] + t[1], p[2] + t[2]];
        let pr = fine.prolongation_from(coarse.mesh()).unwrap();
        let carried = fine.prolong(&pr, &mapped(&coarse, shift), None).unwrap();
        let exact = mapped(&fine, shift);
        // the components the rigid-mode pins fix keep their reference values
        let mut d: f64 = 0.0;
        for (n, (a, b)) in carried.x.iter().zip(&exact.x).enumerate() {
            for k in 0..3 {
                let want = match fine.dofs().eq(n, k) {
                    Some(_) => b[k],
                    None => fine.mesh().nodes[n][k],
                };
                d = d.max((a[k] - want).abs());
            }
        }
        assert!(d < 1e-14, "{kind:?}: {d:e}");
    }
}

/// A smooth deformation (a dilation with a twist and an axial stretch, the kind an inflation
/// makes) carried from 16, 32 and 64 around to twice as many: the largest nodal error falls at
/// the element's order, h² for the 4-node element (the chord's sagitta: the fine nodes off the
/// coarse surface) and towards h³ for the 9-node one. Measured ratios per halving: 4-node 3.88
/// and 3.98; 9-node 6.06 and 6.97 (the largest error at a cap's cube-sphere corner, where three
/// elements meet); asserted above 2^1.9 = 3.73 and 2^2.5 = 5.66.
#[test]
fn a_smooth_field_carries_over_at_the_elements_order() {
    let f = |p: [f64; 3]| {
        let (c, s) = (0.1 * p[2]).sin_cos();
        [
            1.3 * (p[0] * s - p[1] * c),
            1.3 * (p[0] * c + p[1] * s),
            1.05 * p[2],
        ]
    };
    for (kind, order) in [(ElementKind::Quad4, 1.9), (ElementKind::Quad9, 2.5)] {
        let errors: Vec<f64> = [16, 32, 64]
            .iter()
            .map(|&n| {
                let coarse = model(tube(kind, n, Symmetry::None, 1.0));
                let fine = model(tube(kind, 2 * n, Symmetry::None, 1.0));
                let pr = fine.prolongation_from(coarse.mesh()).unwrap();
                let carried = fine.prolong(&pr, &mapped(&coarse, f), None).unwrap();
                distance(&carried.x, &mapped(&fine, f).x)
            })
            .collect();
        for w in errors.windows(2) {
            let ratio = w[0] / w[1];
            eprintln!("{kind:?}: {:.3e} → {:.3e}, ratio {ratio:.2}", w[0], w[1]);
            assert!(ratio > 2f64.powf(order), "{kind:?}: {errors:?}");
        }
    }
}

/// A mesh that is not on the coarse surface (radius 1.2 against 1) is refused, naming the node.
#[test]
fn a_mesh_off_the_coarse_surface_is_refused() {
    let coarse = model(tube(ElementKind::Quad4, 16, Symmetry::Eighth, 1.0));
    let fine = model(tube(ElementKind::Quad4, 32, Symmetry::Eighth, 1.2));
    let e = fine.prolongation_from(coarse.mesh()).unwrap_err();
    assert!(matches!(e, FemError::Prolong { .. }), "{e:?}");
    let text = e.to_string();
    assert!(
        text.contains("node") && text.contains("coarse surface"),
        "{text}"
    );
}

/// A coarse state pressed flat onto the plate y = 0.9 (every node above it moved onto it):
/// no carried node is inside the plate, and a node whose coarse nodes are all on it is on it
/// (to round-off); without the chord rule the reference sagitta between coarse nodes
/// ((2π/32)²/8 = 4.8e-3 R at 32 around, with the 1.1 dilation on top) puts the fine nodes
/// between them inside: measured 9.4e-3 R deep, asserted deeper than 1e-4 R (any depth far above
/// round-off shows the rule acted).
#[test]
fn a_state_pressed_flat_stays_on_its_plane() {
    let coarse = model(tube(ElementKind::Quad4, 32, Symmetry::Eighth, 1.0));
    let fine = model(tube(ElementKind::Quad4, 64, Symmetry::Eighth, 1.0));
    let flat = |p: [f64; 3]| [1.1 * p[0], (1.1 * p[1]).min(0.9), p[2]];
    let contact = Contact::plates(0.9, 1e6);
    let pr = fine.prolongation_from(coarse.mesh()).unwrap();
    let coarse_state = mapped(&coarse, flat);
    let carried = fine.prolong(&pr, &coarse_state, Some(&contact)).unwrap();
    let plate = contact.planes[0];
    let inside = carried
        .x
        .iter()
        .map(|&x| plate.gap(x))
        .fold(f64::INFINITY, f64::min);
    assert!(inside > -1e-14, "{inside:e}");
    // the fine nodes in the flat's interior (reference y above the coarse flat's edge by a
    // coarse element) are on the plate
    let on = fine
        .mesh()
        .nodes
        .iter()
        .zip(&carried.x)
        .filter(|(p, _)| 1.1 * p[1] > 0.9 + 0.25)
        .map(|(_, &x)| plate.gap(x).abs())
        .fold(0.0, f64::max);
    assert!(on < 1e-14, "{on:e}");
    // and the chord rule did act: the plain interpolation puts them inside
    let plain = fine.prolong(&pr, &coarse_state, None).unwrap();
    let deepest = plain.x.iter().map(|&x| plate.gap(x)).fold(0.0, f64::min);
    assert!(deepest < -1e-4, "{deepest:e}");
}

/// The inflation under ϖ = 0.4 converged on 16 around and carried to 32: Newton converges to
/// the fine mesh's own equilibrium (within 1e-8 R of the solve from the reference; the
/// tolerance 1e-9 is on the residual) in fewer iterations than that solve (measured 3 against
/// 5, 4-node; 3 against 6, 9-node; 4.8e-12 and 1.8e-15 R apart).
#[test]
fn a_carried_inflation_converges_to_the_fine_meshs_own_equilibrium() {
    for kind in [ElementKind::Quad4, ElementKind::Quad9] {
        let load = Load::pressure(0.4);
        let mut coarse = model(tube(kind, 16, Symmetry::Eighth, 1.0));
        let mut cs = coarse.reference_state();
        coarse.solve(&mut cs, &load).unwrap();
        let mut fine = model(tube(kind, 32, Symmetry::Eighth, 1.0));
        let mut own = fine.reference_state();
        let direct = fine.solve(&mut own, &load).unwrap();
        let pr = fine.prolongation_from(coarse.mesh()).unwrap();
        let mut carried = fine.prolong(&pr, &cs, None).unwrap();
        let guided = fine.solve(&mut carried, &load).unwrap();
        let d = distance(&carried.x, &own.x);
        eprintln!(
            "{kind:?}: {} iterations from the coarse state, {} from the reference; {d:.1e} R apart",
            guided.iterations, direct.iterations
        );
        assert!(d < 1e-8, "{kind:?}: {d:e}");
        assert!(guided.iterations < direct.iterations, "{kind:?}");
    }
}

/// A guide whose states lead nowhere (every node thrown 0.4 R off in a fixed pattern): its
/// step fails, is cut back, and the stage finishes without it, at the unguided stage's end
/// (within 1e-8 R).
#[test]
fn a_failing_guide_is_cut_back_and_dropped() {
    struct Wild(Vec<f64>);
    impl Guide for Wild {
        fn fractions(&self) -> &[f64] {
            &self.0
        }
        fn state(&self, model: &Model, _k: usize, _load: &Load) -> Result<State, FemError> {
            Ok(mapped(model, |p| {
                let s = (7.0 * p[0] + 13.0 * p[1] + 3.0 * p[2]).sin();
                [p[0] + 0.4 * s, p[1] - 0.4 * s, p[2] + 0.4 * s]
            }))
        }
    }
    let stage = Stage {
        index: 1,
        from: 0.0,
        to: 0.4,
        settings: StepSettings {
            initial_steps: 2,
            ..StepSettings::default()
        },
    };
    let end = |guide: Option<&dyn Guide>| {
        let mut m = model(tube(ElementKind::Quad4, 16, Symmetry::Eighth, 1.0));
        let mut st = m.reference_state();
        let mut cuts = 0;
        run_stage_refitted(
            &mut m,
            &mut st,
            &stage,
            None,
            Load::pressure,
            |_, _, info| {
                cuts = info.progress.cuts;
                Ok::<(), FemError>(())
            },
            None,
            guide,
        )
        .unwrap();
        (st, cuts)
    };
    let (plain, plain_cuts) = end(None);
    let (guided, guided_cuts) = end(Some(&Wild(vec![0.5, 1.0])));
    assert_eq!(plain_cuts, 0);
    assert!(guided_cuts >= 1, "the wild guide's step converged");
    let d = distance(&guided.x, &plain.x);
    assert!(d < 1e-8, "{d:e}");
}
