//! `tubemem.atlas`: an atlas file run on threads of this process or on a Dask cluster, as an
//! xarray Dataset (also written as atlas.nc). The members run the same Rust code wherever they
//! run, and the fits are made here from their results, so a cluster's atlas is the local one
//! bit for bit.

use crate::errors::TubememError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use std::path::{Path, PathBuf};
use tubemem_app::atlas::{self as app_atlas, Atlas, MemberResult};

fn value_error(e: impl std::error::Error + 'static) -> PyErr {
    PyValueError::new_err(tubemem_app::error_chain(&e))
}

/// One atlas member on this process (a Dask worker calls it): runs it into `dir`, writes its
/// member.json, and returns its result as JSON (exact floats).
#[pyfunction]
pub(crate) fn _atlas_member(
    py: Python<'_>,
    atlas_text: String,
    base_dir: PathBuf,
    index: usize,
    dir: PathBuf,
) -> PyResult<String> {
    let atlas = Atlas::parse(&atlas_text, &base_dir).map_err(value_error)?;
    let m = atlas
        .members
        .get(index)
        .ok_or_else(|| PyValueError::new_err(format!("the atlas has no member {index}")))?
        .clone();
    let json = py.detach(|| {
        let r = app_atlas::member::run(&atlas, &m, &dir);
        let json = serde_json::to_string_pretty(&r).expect("plain data serializes");
        tubemem_app::output_file::write_whole(&dir.join("member.json"), json.as_bytes())
            .map(|()| json)
    });
    json.map_err(|e| TubememError::new_err(e.chain()))
}

/// Run the atlas file `atlas` (a path) into `out` and return an xarray Dataset with dimensions
/// (lambda_s_star, rho, length_ratio) for the per-run errors `error_<q>`, `fe_<q>`, `gps_<q>`
/// (q in the atlas's quantities), (lambda_s_star, rho, epsilon) for `min_length_ratio_<q>`, and
/// (lambda_s_star, rho) for the law's `c_<q>`, `a_<q>`, `fit_residual_<q>` and `flag_<q>` (""
/// where the law holds). Flagged points have NaN where a number would be. The files are those of
/// `tubemem atlas` (atlas.csv, runs.csv, atlas.json, figures/) plus atlas.nc.
/// By default the members run on `workers` threads (default the CPU count); with `client=` (a
/// `dask.distributed.Client`) on its cluster, one task per member, with the same results bit
/// for bit. A folder holding the same atlas is resumed. `progress`: a callable given
/// {"member", "done", "total", "error"} as each member finishes.
#[pyfunction]
#[pyo3(signature = (atlas, out, client=None, workers=None, progress=None))]
pub(crate) fn atlas<'py>(
    py: Python<'py>,
    atlas: PathBuf,
    out: PathBuf,
    client: Option<&Bound<'py, PyAny>>,
    workers: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let workers = workers
        .map(|w| crate::convert::int_arg(w, "workers", 1, 4096, "at least 1 (and at most 4096)"))
        .transpose()?;
    let text = tubemem_mesh::io::read_text_limited(&atlas, tubemem_app::case::MAX_CASE_FILE_BYTES)
        .map_err(|e| PyValueError::new_err(format!("cannot read {}: {e}", atlas.display())))?;
    let base = atlas
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    let a = Atlas::parse(&text, &base).map_err(|e| {
        PyValueError::new_err(format!(
            "{}: {}",
            atlas.display(),
            tubemem_app::error_chain(&e)
        ))
    })?;
    // what the end needs, checked before any member runs: the Dataset (xarray) and atlas.nc
    // (written with the scipy engine)
    for (module, why) in [
        ("xarray", "the atlas's Dataset"),
        ("scipy", "atlas.nc (xarray's scipy engine)"),
    ] {
        if py.import(module).is_err() {
            return Err(pyo3::exceptions::PyImportError::new_err(format!(
                "atlas: the Python package `{module}` is needed for {why} and cannot be imported; install it (pip install {module}) before running the atlas"
            )));
        }
    }
    if let Some(c) = client {
        if !(c.hasattr("map")? && c.hasattr("gather")?) {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "atlas: client must be a dask.distributed.Client (with map and gather), not {}; connect one with dask.distributed.Client(\"tcp://host:8786\")",
                c.repr().map_or_else(|_| "?".to_string(), |r| r.to_string())
            )));
        }
    }
    let n = a.members.len();
    let call = |py: Python<'_>, r: &MemberResult, done: usize| -> PyResult<()> {
        if let Some(cb) = progress {
            let d = PyDict::new(py);
            d.set_item("member", &r.name)?;
            d.set_item("done", done)?;
            d.set_item("total", n)?;
            d.set_item("error", r.error.clone())?;
            cb.call1((d,))?;
        }
        Ok(())
    };
    let results: Vec<MemberResult> = match client {
        None => {
            let workers = workers
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |c| c.get()));
            let (tx, rx) = std::sync::mpsc::channel::<(MemberResult, usize)>();
            let outcome = py.detach(|| {
                app_atlas::run(&a, &text, &out, workers, &|p| {
                    let _ = tx.send((p.result.clone(), p.done));
                })
            });
            drop(tx);
            for (r, done) in rx.try_iter() {
                call(py, &r, done)?;
            }
            let o = outcome.map_err(|e| TubememError::new_err(tubemem_app::error_chain(&e)))?;
            if !o.missing.is_empty() {
                return Err(TubememError::new_err(format!(
                    "interrupted: {} members not run ({}); call again to run them",
                    o.missing.len(),
                    app_atlas::missing_summary(&o.missing)
                )));
            }
            o.results
        }
        Some(client) => {
            // held until the atlas is assembled: a second atlas into `out` is refused
            let _lock = app_atlas::prepare(&text, &out)
                .map_err(|e| TubememError::new_err(tubemem_app::error_chain(&e)))?;
            let mut slots: Vec<Option<MemberResult>> = a
                .members
                .iter()
                .map(|m| app_atlas::earlier_result(&out, m))
                .collect();
            let todo: Vec<usize> = (0..n).filter(|&i| slots[i].is_none()).collect();
            let one = py.import("tubemem")?.getattr("_atlas_member")?;
            let texts = vec![text.clone(); todo.len()];
            let bases = vec![base.display().to_string(); todo.len()];
            let dirs: Vec<String> = todo
                .iter()
                .map(|&i| {
                    app_atlas::member_dir(&out, &a.members[i].name)
                        .display()
                        .to_string()
                })
                .collect();
            let kwargs = PyDict::new(py);
            kwargs.set_item("pure", false)?;
            let futures = client.call_method(
                "map",
                (one, texts, bases, todo.clone(), dirs),
                Some(&kwargs),
            )?;
            let gathered = client.call_method1("gather", (futures,))?;
            let mut done = n - todo.len();
            for (k, j) in gathered.try_iter()?.enumerate() {
                let json: String = j?.extract()?;
                let r: MemberResult = serde_json::from_str(&json)
                    .map_err(|e| TubememError::new_err(format!("a worker's result: {e}")))?;
                done += 1;
                call(py, &r, done)?;
                slots[todo[k]] = Some(r);
            }
            let results: Vec<MemberResult> = slots.into_iter().flatten().collect();
            app_atlas::assemble(&a, &results, &out)
                .map_err(|e| TubememError::new_err(tubemem_app::error_chain(&e)))?;
            results
        }
    };
    let points = app_atlas::fit::points(&a, &results);
    let ds = dataset(py, &a, &results, &points)?;
    let nc = out.join("atlas.nc");
    let kw = PyDict::new(py);
    kw.set_item("engine", "scipy")?;
    ds.call_method("to_netcdf", (nc.display().to_string(),), Some(&kw))?;
    Ok(ds)
}

fn dataset<'py>(
    py: Python<'py>,
    a: &Atlas,
    results: &[MemberResult],
    points: &[app_atlas::Point],
) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let s = &a.spec;
    let (ns, nr, nl, ne) = (
        s.stretches.len(),
        s.rho.len(),
        s.lengths.len(),
        s.epsilon.len(),
    );
    let vars = PyDict::new(py);
    let arr = |v: Vec<f64>, shape: &[usize]| -> PyResult<Bound<'py, PyAny>> {
        np.call_method1("array", (v,))?
            .call_method1("reshape", (PyTuple::new(py, shape)?,))
    };
    let d3 = PyTuple::new(py, ["lambda_s_star", "rho", "length_ratio"])?;
    let de = PyTuple::new(py, ["lambda_s_star", "rho", "epsilon"])?;
    let d2 = PyTuple::new(py, ["lambda_s_star", "rho"])?;
    for q in &s.quantities {
        let qi = app_atlas::spec::QUANTITIES
            .iter()
            .position(|x| x == q)
            .expect("validated");
        let (mut err, mut fe, mut gps) = (vec![], vec![], vec![]);
        for &st in &s.stretches {
            for &rho in &s.rho {
                for &l in &s.lengths {
                    let v = results
                        .iter()
                        .find(|r| r.stretch == st && r.length == l)
                        .and_then(|r| r.level(rho))
                        .and_then(|lv| lv.values[qi]);
                    err.push(v.map_or(f64::NAN, |v| v.error()));
                    fe.push(v.map_or(f64::NAN, |v| v.fe));
                    gps.push(v.map_or(f64::NAN, |v| v.gps));
                }
            }
        }
        let (mut min, mut c, mut amp, mut res) = (vec![], vec![], vec![], vec![]);
        let flags = PyList::empty(py);
        for &st in &s.stretches {
            for &rho in &s.rho {
                let p = points
                    .iter()
                    .find(|p| p.stretch == st && p.rho == rho && &p.quantity == q)
                    .expect("a point per grid value");
                min.extend(p.min_length.iter().map(|m| m.unwrap_or(f64::NAN)));
                let valid = p.flag.is_none();
                let f = p.fit.filter(|_| valid);
                c.push(f.map_or(f64::NAN, |f| f.c));
                amp.push(f.map_or(f64::NAN, |f| f.a));
                res.push(p.fit.map_or(f64::NAN, |f| f.relative_residual));
                flags.append(p.flag.as_ref().map_or("", |f| f.flag.as_str()))?;
            }
        }
        vars.set_item(format!("error_{q}"), (&d3, arr(err, &[ns, nr, nl])?))?;
        vars.set_item(format!("fe_{q}"), (&d3, arr(fe, &[ns, nr, nl])?))?;
        vars.set_item(format!("gps_{q}"), (&d3, arr(gps, &[ns, nr, nl])?))?;
        vars.set_item(
            format!("min_length_ratio_{q}"),
            (&de, arr(min, &[ns, nr, ne])?),
        )?;
        vars.set_item(format!("c_{q}"), (&d2, arr(c, &[ns, nr])?))?;
        vars.set_item(format!("a_{q}"), (&d2, arr(amp, &[ns, nr])?))?;
        vars.set_item(format!("fit_residual_{q}"), (&d2, arr(res, &[ns, nr])?))?;
        let fl = np
            .call_method1("array", (flags,))?
            .call_method1("reshape", (PyTuple::new(py, [ns, nr])?,))?;
        vars.set_item(format!("flag_{q}"), (&d2, fl))?;
    }
    let coords = PyDict::new(py);
    coords.set_item("lambda_s_star", s.stretches.clone())?;
    coords.set_item("rho", s.rho.clone())?;
    coords.set_item("length_ratio", s.lengths.clone())?;
    coords.set_item("epsilon", s.epsilon.clone())?;
    let attrs = PyDict::new(py);
    attrs.set_item("law", app_atlas::fit::law_name(s.law))?;
    attrs.set_item(
        "material",
        tubemem_app::figures::overlay::law_label(&a.material),
    )?;
    attrs.set_item("tubemem", env!("CARGO_PKG_VERSION"))?;
    let kw = PyDict::new(py);
    kw.set_item("data_vars", vars)?;
    kw.set_item("coords", coords)?;
    kw.set_item("attrs", attrs)?;
    py.import("xarray")?.getattr("Dataset")?.call((), Some(&kw))
}
