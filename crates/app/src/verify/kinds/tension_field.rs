//! `tension-field`: wrinkling against a closed form ([`tubemem_fem::tension_field`]): a flat
//! quarter annulus pulled at both rims, with the case's law, wrinkling model and element, on
//! a mesh family of 8·2^k elements around and 6·2^k radially (k = `start` … `start` +
//! `meshes` − 1, default 1…4). The case's tube and stages are not used. Held on the finest
//! mesh: the wrinkled radius's relative error (`wrinkle_radius`), the resultants' L2 error over
//! T_out against the tension-field solution (`stress`) or against Lamé's (`lame_stress`: the
//! law without relaxation, which carries the compression); their orders and the smallest hoop
//! resultant reported.

use super::{plot, KindResult};
use crate::case::Case;
use crate::figures::{series_color, Figure, Markers, Series, Stroke};
use crate::verify::suite::{Check, DEFAULT_ANNULUS};
use crate::verify::{CheckResult, Measure, VerifyOptions};
use std::path::Path;
use tubemem_fem::model::Model;
use tubemem_fem::tension_field::{solve_annulus, Annulus, AnnulusSolution};

kind!(
    /// The `tension-field` kind.
    TensionField,
    "tension-field",
    tension_field
);

fn tension_field(c: &Check, _dir: &Path, _opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let case = Case::parse(&c.case_text).map_err(|e| crate::error_chain(&e))?;
    // the tractions are given per μH: the law's resultants carry its shear modulus
    let shape = c.spec.annulus.unwrap_or(DEFAULT_ANNULUS);
    let mu = case.material.shear_modulus();
    let a = Annulus {
        t_in: shape.t_in * mu,
        t_out: shape.t_out * mu,
        ..shape
    };
    let n = c.spec.meshes.unwrap_or(4);
    let start = c.spec.start.unwrap_or(1).max(0) as u32;
    let exact_l = a.wrinkle_radius();
    let mut sols: Vec<(usize, AnnulusSolution)> = vec![];
    for k in start..start + n as u32 {
        let m = 2usize.pow(k);
        let mesh =
            tubemem_mesh::sheet::quarter_annulus(case.mesh.element, a.r_in, a.r_out, 8 * m, 6 * m)
                .map_err(|e| e.to_string())?;
        let law = case
            .material
            .build_with(case.solver.wrinkling)
            .map_err(|e| e.to_string())?;
        let model = Model::new(mesh, law).map_err(|e| crate::error_chain(&e))?;
        let s = solve_annulus(model, &a, 4)
            .map_err(|e| format!("mesh {}: {}", 8 * m, crate::error_chain(&e)))?;
        sols.push((8 * m, s));
    }
    let last = &sols.last().ok_or("no mesh")?.1;
    let order = |f: &dyn Fn(&AnnulusSolution) -> f64| {
        let k = sols.len();
        if k < 2 {
            return f64::NAN;
        }
        (f(&sols[k - 2].1) / f(&sols[k - 1].1)).log2()
    };
    let l_err = |s: &AnnulusSolution| match (s.wrinkle_radius, exact_l) {
        (Some(l), Some(e)) => (l / e - 1.0).abs(),
        _ => f64::NAN,
    };
    for (q, tol) in &c.spec.tolerance {
        let (measured, note) = match q.as_str() {
            "wrinkle_radius" if last.wrinkle_radius.is_none() => {
                r.measures.push(Measure::missing(
                    q,
                    tol,
                    "the FE shows no wrinkled zone (its hoop resultant is nowhere zero)",
                ));
                continue;
            }
            "wrinkle_radius" => (
                l_err(last),
                format!(
                    "FE L = {}, closed form {}; order {:.2}",
                    radius(last.wrinkle_radius),
                    radius(exact_l),
                    order(&l_err)
                ),
            ),
            "stress" => (
                last.error_tension_field,
                format!("order {:.2}", order(&|s| s.error_tension_field)),
            ),
            "lame_stress" => (
                last.error_lame,
                format!("order {:.2}", order(&|s| s.error_lame)),
            ),
            _ => continue,
        };
        r.measures.push(Measure::held(
            q,
            measured,
            tol,
            format!("{} elements around; {note}", sols.last().map_or(0, |s| s.0)),
        ));
    }
    r.measures.push(Measure::reported(
        "smallest hoop resultant / T_out",
        last.min_hoop,
        if last.min_hoop < -1e-6 {
            "negative: the membrane carries a compression (Lamé's at the hub)".into()
        } else {
            "no compression beyond Newton's tolerance (1e-8 of the rims' load)".into()
        },
    ));
    r.details = serde_json::json!({
        "annulus": a,
        "wrinkle_radius": exact_l,
        "meshes": sols.iter().map(|(around, s)| serde_json::json!({
            "around": around, "equations": s.equations, "wrinkle_radius": s.wrinkle_radius,
            "error_tension_field": s.error_tension_field, "error_lame": s.error_lame,
            "min_hoop": s.min_hoop,
        })).collect::<Vec<_>>(),
    });
    // the finest mesh's resultants against both closed forms, along the radius
    let fine = |f: fn(&Annulus, f64) -> [f64; 2], i: usize, label: &str, color, stroke| Series {
        label: label.into(),
        points: (0..=200)
            .map(|k| {
                let rr = a.r_in + (a.r_out - a.r_in) * k as f64 / 200.0;
                (rr, f(&a, rr)[i] / a.t_out)
            })
            .collect(),
        color,
        stroke,
        width: 2,
    };
    let series = vec![
        fine(
            Annulus::tension_field,
            0,
            "N_rr, tension field",
            series_color(0),
            Stroke::Solid,
        ),
        fine(
            Annulus::tension_field,
            1,
            "N_θθ, tension field",
            series_color(1),
            Stroke::Solid,
        ),
        fine(
            Annulus::lame,
            1,
            "N_θθ, Lamé (no wrinkles)",
            series_color(5),
            Stroke::Dashed,
        ),
    ];
    let markers = vec![
        Markers {
            label: "N_rr, FE".into(),
            points: last
                .points
                .iter()
                .step_by(7)
                .map(|p| (p.r, p.n_rr / a.t_out))
                .collect(),
            color: series_color(0),
            hollow: true,
        },
        Markers {
            label: "N_θθ, FE".into(),
            points: last
                .points
                .iter()
                .step_by(7)
                .map(|p| (p.r, p.n_tt / a.t_out))
                .collect(),
            color: series_color(1),
            hollow: true,
        },
    ];
    plot(
        &Figure {
            markers,
            y_from_zero: false,
            notes: vec![format!(
                "wrinkled radius: closed form {}, FE {}",
                radius(exact_l),
                radius(last.wrinkle_radius)
            )],
            ..Figure::new(
                format!("{}: the annulus pulled at both rims", c.spec.name),
                "reference radius r / R_in",
                "resultant / T_out",
                series,
            )
        },
        r,
    );
    Ok(None)
}

/// A wrinkled radius, or "none" (no wrinkled zone).
fn radius(l: Option<f64>) -> String {
    l.map_or("none".into(), |l| format!("{l:.6}"))
}
