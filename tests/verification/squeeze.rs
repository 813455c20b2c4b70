//! Tubes squeezed between plates with the gas closed in, against the GPS flattening
//! (eqs. 76–77) and the GPS section under the FE's own pressure (eq. 76 without the gas law).
use tubemem_fem::post::Ring;
use tubemem_fixtures::{abb30, squeeze_tube};
use tubemem_gps::{flatten, section_at_pressure, Hypothesis};

/// Source: GPS flattening, eqs. (76)–(77), at the FE's own λs* and the same ρ = 0.8.
/// What differs is physics GPS leaves out — the caps hold gas that the plates do not squeeze,
/// so the pressure rises less, a 1/L law (README, "end effect") — plus discretization. Checked:
/// (1) every error falls when L/R doubles from 20 to 40 (the end effect); (2) at L/R = 40 the
/// errors stay within bounds set from this mesh's measured values with margin (measured with
/// κ = ϖ*J*/1e-3: ϖ −0.34 %, λs −0.17 %, λz −0.12 %, χ −1.2 %, force −1.6 %; bounds 0.6 %,
/// 0.3 %, 0.3 %, 2 %, 2.5 %).
#[test]
fn squeeze_approaches_gps_as_the_tube_gets_longer() {
    let law = abb30();
    let errs = |l: f64| {
        let s = squeeze_tube(l, 32, 1e-3);
        let g = flatten(&law, Hypothesis::Gps, s.initial_stretch, 0.8).unwrap();
        let r = |a: f64, b: f64| (a - b) / b;
        [
            r(s.midspan.w, g.w),
            r(s.midspan.lambda_s, g.lambda_s),
            r(s.midspan.lambda_z, g.lambda_z),
            r(s.contact.chi, g.chi),
            r(s.contact.force, g.force),
        ]
    };
    let (e20, e40) = (errs(20.0), errs(40.0));
    let names = ["ϖ", "λs", "λz", "χ", "force"];
    for k in 0..5 {
        assert!(
            e40[k].abs() < e20[k].abs(),
            "{}: error {} at L/R = 40 not below {} at 20",
            names[k],
            e40[k],
            e20[k]
        );
    }
    let bounds = [6e-3, 3e-3, 3e-3, 2e-2, 2.5e-2];
    for k in 0..5 {
        assert!(
            e40[k].abs() < bounds[k],
            "{}: {} at L/R = 40",
            names[k],
            e40[k]
        );
    }
}

/// Penalty: the penetration is about p J/κ (`contact::penalty_for`), so ten times κ gives a
/// tenth of the penetration (measured ratio 9.79; bound: within 20 % of 10), and the mid-span
/// pressure moves by less than 0.5 % (measured 1.2e-3) between κ = ϖ*J*/1e-3 and ϖ*J*/1e-4
/// (the penalty error is small against the end effect).
#[test]
fn penetration_falls_as_the_penalty_grows() {
    let a = squeeze_tube(10.0, 16, 1e-3);
    let b = squeeze_tube(10.0, 16, 1e-4);
    let ratio = a.contact.penetration / b.contact.penetration;
    assert!(
        (ratio / 10.0 - 1.0).abs() < 0.2,
        "penetration ratio {ratio}"
    );
    assert!((a.midspan.w / b.midspan.w - 1.0).abs() < 5e-3);
}

/// The mid-span of the squeezed tube against the GPS cross-section under the FE's *own* gas
/// pressure (eq. 76 without the gas law, `tubemem_gps::section_at_pressure`). This is the
/// translation-invariance claim itself, with the end effect that travels through the shared gas
/// (the ends keep gas the plates do not squeeze, so ϖ rises less) taken out.
/// Measured here (L/R = 20, along = 4 L/R, ρ = 0.8, κ = ϖ*J*/1e-3), relative errors:
///
/// | around | ϖ vs Boyle GPS | λs vs local | λz vs local | χ vs local |
/// |---|---|---|---|---|
/// | 32 | −1.00 % | −7.7e-4 | −5.9e-4 | −1.00 % |
/// | 64 | −1.32 % | −1.8e-5 | −6.7e-5 | −0.31 % |
///
/// Bounds: at 64 around λs and λz within 2e-4 of the local section (3× the larger measured
/// value) and χ within 0.6 % (2× measured; the contact edge is resolved to O(h)); every local
/// error falls from 32 to 64 around; and the ϖ error against the Boyle GPS stays at least 20×
/// the local stretch errors: the end effect passes through the gas, not the section.
#[test]
fn squeezed_midspan_obeys_the_gps_section_at_its_own_pressure() {
    let law = abb30();
    let errs = |around: usize| {
        let s = squeeze_tube(20.0, around, 1e-3);
        let g = flatten(&law, Hypothesis::Gps, s.initial_stretch, 0.8).unwrap();
        let l = section_at_pressure(&law, 0.8, s.midspan.w, [g.lambda_s, g.lambda_z]).unwrap();
        let r = |a: f64, b: f64| (a - b) / b;
        [
            r(s.midspan.w, g.w),
            r(s.midspan.lambda_s, l.lambda_s),
            r(s.midspan.lambda_z, l.lambda_z),
            r(s.contact.chi, l.chi),
        ]
    };
    let (e32, e64) = (errs(32), errs(64));
    for k in 1..4 {
        assert!(e64[k].abs() < e32[k].abs(), "{k}: {e32:?} -> {e64:?}");
    }
    assert!(e64[1].abs() < 2e-4 && e64[2].abs() < 2e-4, "{e64:?}");
    assert!(e64[3].abs() < 6e-3, "{e64:?}");
    assert!(
        e64[0].abs() > 20.0 * e64[1].abs().max(e64[2].abs()),
        "{e64:?}"
    );
}

/// Force balance of the squeezed tube (L/R = 20, ρ = 0.8, κ = ϖ*J*/1e-3), two ways.
/// (1) The total plate force of the output (`total_force`, integrated contact pressure) equals
///     the plates' reaction: the sum along n of the contact nodal forces that the assembled
///     residual carries (the residual with the plates minus the one without), to rounding
///     (1e-10 relative: the two residuals are O(1) and their difference O(0.1)).
/// (2) Equilibrium of the upper half of the mid-span section, cut at y = 0 where the membrane
///     is vertical (symmetry): per unit length, plate force = gas pressure × the section's width
///     at the cut − the two hoop resultants there, i.e. π·force = 2ϖ x_eq − 2N_s. This holds for
///     any translation-invariant section (GPS: N_s = ϖρ and x_eq = ρ + πχ/2 give force = ϖχ,
///     eq. 80); here the three terms come from different FE outputs (contact traction, node
///     position, ring-averaged Cauchy resultant). Measured relative imbalance: −4.53 %, −1.03 %,
///     −0.24 % at 16, 32, 64 around — second order (ratios 4.4, 4.2). Checked: below 0.5 % at
///     64 around and falling by more than 3× from 32.
#[test]
fn plate_force_balances_the_contact_reaction_and_the_section() {
    let imbalance = |around: usize| {
        let s = squeeze_tube(20.0, around, 1e-3);
        let model = &s.model;
        // the top plate alone: its reaction is the y-sum of its nodal contact forces
        let mut top = s.plates.clone();
        top.planes.retain(|p| p.normal[1] < 0.0);
        let with = model.assemble(&s.state.x, false, Some(&top)).unwrap();
        let without = model.assemble(&s.state.x, false, None).unwrap();
        let mut reaction = 0.0;
        for i in 0..model.mesh().nodes.len() {
            if let Some(k) = model.dofs().eq(i, 1) {
                reaction += with.f_int[k] - without.f_int[k];
            }
        }
        // the eighth model holds a quarter of one plate's contact
        let reaction = model.multiplicity() / 2.0 * reaction;
        assert!(
            (s.contact.total_force - reaction).abs() < 1e-10 * reaction,
            "{} vs {reaction}",
            s.contact.total_force
        );
        let ring = Ring::midspan(model);
        let x_eq = ring
            .nodes
            .iter()
            .map(|&i| s.state.x[i][0])
            .fold(0.0, f64::max);
        std::f64::consts::PI * s.contact.force / (2.0 * s.midspan.w * x_eq - 2.0 * s.midspan.n_s)
            - 1.0
    };
    let (e32, e64) = (imbalance(32), imbalance(64));
    assert!(e64.abs() < 5e-3, "{e64}");
    assert!(e32.abs() > 3.0 * e64.abs(), "{e32} -> {e64}");
}
