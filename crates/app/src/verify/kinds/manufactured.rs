//! `manufactured`: the method of manufactured solutions on the check's case
//! ([`tubemem_fem::manufactured`]): its law (any, a `[material]` table written as text
//! included, with the case's wrinkling model), its tube (`[geometry]`: radius, length) and its
//! element, on a mesh family: a generated mesh scaled by 2 (`start`, `meshes`), or a user's mesh
//! file and its uniform refinements (each quad split in four, the new nodes on the exact capped
//! tube; 4-node meshes of the case's tube). The case's stages are not run: the check solves the
//! manufactured problem (`loading`, `pressure`). Measured: the position error in L2 (held to
//! `expected_order` on the finest two ratios), in L∞ at the Gauss points and the nodes, and
//! the resultants' L2 error (their orders reported), and the pressure where the loading finds
//! one. With `plates = true` the state is squeezed between the plates y = ±1.15 R
//! ([`Pressed`]): the FE must find the contact zone and the manufactured contact pressure with
//! its augmented Lagrangian at the nodes; the contact pressure's L2 order and the largest
//! penetration are reported too. Its families need finer meshes (32 to 256 around; measured in
//! crates/fem/tests/manufactured.rs).

use super::{plot, KindResult};
use crate::case::Case;
use crate::figures::{series_color, Figure, Series, Stroke};
use crate::verify::suite::Check;
use crate::verify::{vary, CheckResult, Measure, VerifyOptions};
use std::path::Path;
use tubemem_fem::contact::ContactPoints;
use tubemem_fem::manufactured::body::Manufactured as Problem;
use tubemem_fem::manufactured::field::{Field, Pressed, TubeField};
use tubemem_fem::manufactured::study::{order, solve, MmsErrors, MmsLoading};
use tubemem_fem::manufactured::surface::CappedTube;
use tubemem_fem::model::Model;

kind!(
    /// The `manufactured` kind.
    Manufactured,
    "manufactured",
    manufactured
);

/// One error measure of a family member.
type Metric = fn(&MmsErrors) -> f64;

/// The manufactured pressure when the check names none.
const DEFAULT_PRESSURE: f64 = 0.4;

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The family's meshes: (elements around, mesh).
fn family(c: &Check, case: &Case, n: usize) -> Result<Vec<(usize, tubemem_mesh::Mesh)>, String> {
    let surface = surface(case);
    if case.mesh.file.is_some() {
        let base = crate::run::build_mesh(case).map_err(|e| crate::error_chain(&e))?;
        // the user's mesh must be a mesh of the case's capped tube
        for (i, p) in base.nodes.iter().enumerate() {
            let q = surface.project(*p);
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            if d > 1e-6 * case.geometry.radius {
                return Err(format!(
                    "the mesh file's node {i} lies {d:.2e} off the case's capped tube (radius {}, length {}): a manufactured check needs a mesh of that tube",
                    case.geometry.radius, case.geometry.length
                ));
            }
        }
        let mut meshes = vec![(0, base)];
        for k in 1..n {
            let next = tubemem_mesh::refine::split(&meshes[k - 1].1, |p| surface.project(p))
                .map_err(err)?;
            meshes.push((k, next));
        }
        // "around" for a user's mesh: 2^k relative to the file's mesh
        return Ok(meshes.into_iter().map(|(k, m)| (1 << k, m)).collect());
    }
    let start = c.spec.start.unwrap_or(0);
    (0..n)
        .map(|k| {
            let f = 2f64.powi(start + k as i32);
            let text = vary(&c.case_text, |t| {
                if let Some(m) = t.get_mut("mesh").and_then(|m| m.as_table_mut()) {
                    for key in ["around", "along", "cap_rows"] {
                        if let Some(v) = m.get(key).and_then(|v| v.as_integer()) {
                            let n = ((v as f64) * f).round().max(1.0) as i64;
                            m.insert(key.into(), toml::Value::Integer(n));
                        }
                    }
                }
            })?;
            let mut member = Case::parse(&text).map_err(|e| crate::error_chain(&e))?;
            member.base_dir = c.base_dir.clone();
            let around = member.mesh.around.unwrap_or(0);
            let mesh = crate::run::build_mesh(&member).map_err(|e| crate::error_chain(&e))?;
            Ok((around, mesh))
        })
        .collect()
}

/// What a family's solve needs besides its field.
struct FamilySolve<'a> {
    case: &'a Case,
    law: &'a dyn tubemem_material::MembraneLaw,
    build: &'a dyn Fn() -> Result<Box<dyn tubemem_material::MembraneLaw>, String>,
    pressure: f64,
    loading: MmsLoading,
    meshes: Vec<(usize, tubemem_mesh::Mesh)>,
}

impl FamilySolve<'_> {
    /// The manufactured problem of `field` solved on every mesh of the family, and the field's
    /// name; a field pressed against planes is held by the FE's contact at the nodes (the
    /// augmented Lagrangian of [`tubemem_fem::manufactured::study`]; the case's `[contact]` is
    /// not used).
    fn solve<F: Field>(self, field: &F) -> Result<(Vec<MmsErrors>, String), String> {
        let problem = Problem {
            field,
            surface: surface(self.case),
            law: self.law,
            pressure: self.pressure,
        };
        let points = if field.planes().is_empty() {
            ContactPoints::Gauss
        } else {
            ContactPoints::Nodal
        };
        let rows = self
            .meshes
            .into_iter()
            .map(|(around, mesh)| {
                let model =
                    Model::new(mesh, (self.build)()?).map_err(|e| crate::error_chain(&e))?;
                solve(model, &problem, self.loading, around, points)
                    .map_err(|e| format!("mesh {around}: {}", crate::error_chain(&e)))
            })
            .collect::<Result<_, String>>()?;
        Ok((rows, field.name()))
    }
}

fn surface(case: &Case) -> CappedTube {
    CappedTube {
        radius: case.geometry.radius,
        half_length: 0.5 * case.geometry.length,
    }
}

/// The family solved, then the orders and the convergence plot.
fn manufactured(c: &Check, dir: &Path, _opts: &VerifyOptions, r: &mut CheckResult) -> KindResult {
    let mut case = Case::parse(&c.case_text).map_err(|e| crate::error_chain(&e))?;
    case.base_dir = c.base_dir.clone();
    if case.geometry.caps != crate::case::Caps::Hemisphere {
        return Err("a manufactured check needs hemispherical caps (the exact surface is a cylinder with hemispheres)".into());
    }
    let n = c.spec.meshes.unwrap_or(4);
    let loading = c.spec.loading.unwrap_or(MmsLoading::Pressure);
    let pressure = match loading {
        MmsLoading::None => 0.0,
        _ => c.spec.pressure.unwrap_or(DEFAULT_PRESSURE),
    };
    let wrinkling = case.solver.wrinkling;
    let law = case.material.build_with(wrinkling).map_err(err)?;
    let build = || case.material.build_with(wrinkling).map_err(err);
    let family = FamilySolve {
        case: &case,
        law: law.as_ref(),
        build: &build,
        pressure,
        loading,
        meshes: family(c, &case, n)?,
    };
    let (radius, length) = (case.geometry.radius, case.geometry.length);
    let (rows, field_name) = if c.spec.plates.unwrap_or(false) {
        family.solve(&Pressed::standard(radius, length))?
    } else {
        family.solve(&TubeField::standard(radius, length))?
    };
    let k = rows.len();
    let ord = |m: fn(&MmsErrors) -> f64| -> [f64; 2] {
        [
            order(
                m(&rows[k - 3]),
                m(&rows[k - 2]),
                rows[k - 3].around,
                rows[k - 2].around,
            ),
            order(
                m(&rows[k - 2]),
                m(&rows[k - 1]),
                rows[k - 2].around,
                rows[k - 1].around,
            ),
        ]
    };
    let expected = c.spec.expected_order.as_ref().ok_or("no expected_order")?;
    for (i, o) in ord(|e| e.l2_position).iter().enumerate() {
        r.measures.push(Measure::expected(
            &format!("L2 position order, meshes {}–{}: ", k - 2 + i, k - 1 + i),
            "p",
            *o,
            expected,
            "observed",
        ));
    }
    for (what, m) in [
        (
            "L∞ position order (Gauss points)",
            (|e: &MmsErrors| e.max_position) as fn(&MmsErrors) -> f64,
        ),
        ("L∞ position order (nodes)", |e| e.max_nodal),
        ("resultants L2 order", |e| e.l2_resultants),
    ] {
        let o = ord(m);
        r.measures.push(Measure::reported(
            what,
            o[1],
            format!("finest two ratios {:.2}, {:.2}", o[0], o[1]),
        ));
    }
    let last = &rows[k - 1];
    r.measures.push(Measure::reported(
        "L2 position error, finest mesh",
        last.l2_position,
        format!("{} equations", last.equations),
    ));
    if c.spec.plates.unwrap_or(false) {
        let o = ord(|e| e.l2_contact);
        r.measures.push(Measure::reported(
            "contact pressure L2 order",
            o[1],
            format!("finest two ratios {:.2}, {:.2}", o[0], o[1]),
        ));
        r.measures.push(Measure::reported(
            "contact pressure L2 error / max q*, finest mesh",
            last.l2_contact,
            format!("largest penetration {:.1e} R", last.penetration),
        ));
    }
    if matches!(loading, MmsLoading::Volume | MmsLoading::Gas) {
        r.measures.push(Measure::reported(
            "pressure error, finest mesh",
            last.pressure.abs(),
            format!("(ϖ_h − ϖ*)/ϖ* = {:+.2e}", last.pressure),
        ));
    }
    r.details = serde_json::json!({
        "field": field_name,
        "law": law.name(),
        "loading": loading.label(),
        "pressure": pressure,
        "meshes": rows,
    });
    let mut measured: Vec<(&str, Metric)> = vec![
        ("L2 position", |e| e.l2_position),
        ("L∞ position", |e| e.max_position),
        ("L2 resultants", |e| e.l2_resultants),
    ];
    if c.spec.plates.unwrap_or(false) {
        measured.push(("L2 contact pressure", |e| e.l2_contact));
    }
    let series: Vec<Series> = measured
        .iter()
        .enumerate()
        .map(|(i, (label, m))| Series {
            label: label.to_string(),
            points: rows
                .iter()
                .map(|e| ((e.around as f64).log10(), m(e).log10()))
                .collect(),
            color: series_color(i),
            stroke: Stroke::Solid,
            width: 2,
        })
        .collect();
    let _ = dir;
    plot(
        &Figure {
            y_from_zero: false,
            notes: vec![format!("{} ({} loading)", law.name(), loading.label())],
            ..Figure::new(
                format!("{}: manufactured solution", c.spec.name),
                "log10 (elements around)",
                "log10 error",
                series,
            )
        },
        r,
    );
    Ok(None)
}
