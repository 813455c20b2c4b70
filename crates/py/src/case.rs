//! `tubemem.Case`: a validated case from keywords, a dict, TOML text or a file, and the case
//! file's names in messages as Python dict paths.

use crate::convert::from_py;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A validated case. `Case(geometry=…, material=…, mesh=…, stage=[…], solver=…, output=…)` takes
/// the case file's tables as keyword arguments; `Case.from_dict(d)`, `Case.from_toml(text)` and
/// `Case.read(path)` the other forms. Validation happens on construction (ValueError naming the
/// table and key); `to_toml()` and `to_dict()` give it back. `tubemem.run` takes it.
#[pyclass(name = "Case", module = "tubemem")]
pub(crate) struct PyCase {
    pub(crate) toml: String,
    pub(crate) base_dir: PathBuf,
}

impl PyCase {
    pub(crate) fn parse(toml: String, base_dir: PathBuf) -> PyResult<Self> {
        tubemem_app::case::Case::parse(&toml)
            .map_err(|e| PyValueError::new_err(tubemem_app::error_chain(&e)))?;
        Ok(Self { toml, base_dir })
    }

    /// A case from a dict of its tables: its errors name dict paths (`material.kuhm`,
    /// `stage[1].target_rho`), not the lines of the TOML it is turned into.
    pub(crate) fn from_value(d: &Bound<'_, PyAny>, base_dir: PathBuf) -> PyResult<Self> {
        // a `Material` as the material table: its dict
        let d = match d.cast::<pyo3::types::PyDict>() {
            Ok(t) => match t.get_item("material")? {
                Some(m) if m.cast::<crate::material::PyMaterial>().is_ok() => {
                    let copy = t.copy()?;
                    let spec = crate::material::spec_of(&m)?;
                    copy.set_item("material", crate::convert::to_py(d.py(), &spec)?)?;
                    copy.into_any()
                }
                _ => d.clone(),
            },
            Err(_) => d.clone(),
        };
        let value: serde_json::Value = from_py(&d, "case")?;
        let table = toml::Value::try_from(value)
            .map_err(|e| PyValueError::new_err(format!("case: {e}")))?;
        let text =
            toml::to_string(&table).map_err(|e| PyValueError::new_err(format!("case: {e}")))?;
        match tubemem_app::case::Case::parse(&text) {
            Ok(_) => Ok(Self {
                toml: text,
                base_dir,
            }),
            Err(e) => Err(PyValueError::new_err(dict_message(
                &tubemem_app::error_chain(&e),
                &text,
            ))),
        }
    }
}

#[pymethods]
impl PyCase {
    #[new]
    #[pyo3(signature = (base_dir=None, **tables))]
    fn new(
        base_dir: Option<PathBuf>,
        tables: Option<&Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<Self> {
        let py_tables = match tables {
            Some(t) => t.clone(),
            None => return Err(PyValueError::new_err("Case: give the case file's tables as keywords (geometry=…, material=…, mesh=…, stage=[…])")),
        };
        Self::from_value(py_tables.as_any(), base_dir.unwrap_or_default())
    }
    #[staticmethod]
    #[pyo3(signature = (d, base_dir=None))]
    fn from_dict(d: &Bound<'_, PyAny>, base_dir: Option<PathBuf>) -> PyResult<Self> {
        Self::from_value(d, base_dir.unwrap_or_default())
    }
    #[staticmethod]
    #[pyo3(signature = (text, base_dir=None))]
    fn from_toml(text: String, base_dir: Option<PathBuf>) -> PyResult<Self> {
        Self::parse(text, base_dir.unwrap_or_default())
    }
    /// Read a case file (user meshes are looked up relative to its folder).
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        let text =
            tubemem_mesh::io::read_text_limited(&path, tubemem_app::case::MAX_CASE_FILE_BYTES)
                .map_err(|e| {
                    PyValueError::new_err(format!("cannot read {}: {e}", path.display()))
                })?;
        Self::parse(text, path.parent().map(PathBuf::from).unwrap_or_default())
    }
    fn to_toml(&self) -> String {
        self.toml.clone()
    }
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("tomllib")?
            .call_method1("loads", (self.toml.as_str(),))
    }
    /// The tube, its law, its mesh and its stages in one line ([`tubemem_app::case::Case::describe`]).
    fn __repr__(&self) -> String {
        match tubemem_app::case::Case::parse(&self.toml) {
            Ok(c) => format!("<tubemem.Case: {}>", c.describe()),
            Err(_) => format!("<tubemem.Case: {} bytes of TOML>", self.toml.len()),
        }
    }
    fn __eq__(&self, other: &Self) -> bool {
        self.toml == other.toml
    }
}

/// The dict path of line `line` (1-based) of the TOML text a case dict was turned into: its
/// table (`stage[k]` for the k-th `[[stage]]`, 0-based as the list) and its key.
pub(crate) fn dict_path(text: &str, line: usize) -> String {
    let mut table = String::new();
    let mut stages = 0usize;
    for (k, l) in text.lines().enumerate() {
        let t = l.trim();
        if let Some(name) = t.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
            let count = if name == "stage" {
                stages += 1;
                stages
            } else {
                1
            };
            table = format!("{name}[{}]", count - 1);
        } else if let Some(name) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            table = name.to_string();
        }
        if k + 1 == line {
            let key = t.split('=').next().unwrap_or("").trim();
            return match (table.is_empty(), key.is_empty() || t.starts_with('[')) {
                (true, _) => key.to_string(),
                (false, true) => table,
                (false, false) => format!("{table}.{key}"),
            };
        }
    }
    table
}

/// A case error as a Python user reads it: a TOML parse error of the generated text becomes
/// the dict path it points at and its reason; the case file's `[[stage]] N: \`key\`` and
/// `[table] \`key\`` become `stage[N-1].key` and `table.key`.
pub(crate) fn dict_message(msg: &str, text: &str) -> String {
    if let Some(rest) = msg.split("TOML parse error at line ").nth(1) {
        let line: usize = rest
            .split(|c: char| !c.is_ascii_digit())
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or(0);
        let reason = rest.lines().last().unwrap_or("").trim();
        let mut path = dict_path(text, line);
        // an unknown key reported at its table: the key itself
        if let Some(key) = reason
            .strip_prefix("unknown field `")
            .and_then(|r| r.split('`').next())
        {
            // (a table's own header line names the key already: an unknown top-level table)
            if path != key && !path.ends_with(&format!(".{key}")) {
                path = format!("{path}.{key}");
            }
        }
        return format!("case dict: {path}: {reason}");
    }
    format!("case dict: {}", pythonic(msg))
}

/// The case file's names in a message, as the dict paths and arguments of the Python API:
/// `[[stage]] N: \`key\`` → `stage[N-1].key`, `[[stage]] N` → `stage[N-1]`, `[table] \`key\``
/// → `table.key`, `[material]: invalid material parameter \`key\`` → `material.key`, and the CLI's `--overwrite`, `--out`, `--resume` → `overwrite=True`, `out`,
/// the CLI's `tubemem run --resume`.
pub(crate) fn pythonic(msg: &str) -> String {
    // the material's own check under the case's table, `[material]: invalid material
    // parameter \`key\` = value: …`, as the other checks name a key: `material.key = value: …`
    let material = msg
        .split_once("[material]: invalid material parameter `")
        .and_then(|(before, after)| {
            let (key, tail) = after.split_once('`')?;
            Some(format!("{before}material.{key}{tail}"))
        });
    let msg = material.as_deref().unwrap_or(msg);
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("[[stage]] ") {
            let digits: String = after.chars().take_while(|c| c.is_ascii_digit()).collect();
            if let Ok(n) = digits.parse::<usize>() {
                let mut tail = &after[digits.len()..];
                let mut path = format!("stage[{}]", n.saturating_sub(1));
                if let Some(key) = tail
                    .strip_prefix(": `")
                    .and_then(|t| t.split_once('`'))
                    .filter(|(k, _)| k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
                {
                    path = format!("{path}.{}", key.0);
                    tail = key.1;
                }
                out.push_str(&path);
                rest = tail;
                continue;
            }
        }
        if let Some(after) = rest.strip_prefix('[') {
            if let Some((name, tail)) = after.split_once("] `") {
                if let Some((key, tail)) = tail.split_once('`') {
                    if !name.is_empty()
                        && name.chars().all(|c| c.is_ascii_lowercase() || c == '_')
                        && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                    {
                        out.push_str(&format!("{name}.{key}"));
                        rest = tail;
                        continue;
                    }
                }
            }
        }
        let c = rest.chars().next().unwrap_or(' ');
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out.replace("--overwrite", "overwrite=True")
        .replace("another --out", "another `out`")
        .replace("--resume", "the CLI's `tubemem run --resume`")
}

/// A case given as a `Case`, a path to a TOML file, TOML text, or a dict of the case file's
/// tables.
pub(crate) fn case_from(
    py: Python<'_>,
    case: &Bound<'_, PyAny>,
    base_dir: Option<PathBuf>,
) -> PyResult<(tubemem_app::case::Case, String)> {
    let invalid =
        |e: tubemem_app::case::CaseError| PyValueError::new_err(tubemem_app::error_chain(&e));
    if let Ok(c) = case.cast::<PyCase>() {
        let c = c.borrow();
        let mut parsed = tubemem_app::case::Case::parse(&c.toml).map_err(invalid)?;
        parsed.base_dir = base_dir.unwrap_or_else(|| c.base_dir.clone());
        return Ok((parsed, "case from Python".into()));
    }
    if case.cast::<pyo3::types::PyDict>().is_ok() {
        let c = PyCase::from_value(case, PathBuf::new())?;
        let mut parsed = tubemem_app::case::Case::parse(&c.toml).map_err(invalid)?;
        parsed.base_dir = base_dir.unwrap_or_default();
        return Ok((parsed, "case dict from Python".into()));
    }
    let text: String = case
        .str()
        .and_then(|s| s.extract())
        .map_err(|_| PyValueError::new_err("case: a path, TOML text or a dict"))?;
    let path = PathBuf::from(&text);
    if !text.contains('\n') && path.is_file() {
        let c = tubemem_app::case::Case::read(&path).map_err(invalid)?;
        return Ok((c, path.display().to_string()));
    }
    let mut c = tubemem_app::case::Case::parse(&text).map_err(invalid)?;
    c.base_dir = base_dir.unwrap_or_default();
    let _ = py;
    Ok((c, "case text from Python".into()))
}

/// The TOML text of a case given in any of `run`'s forms.
pub(crate) fn case_text(py: Python<'_>, case: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(c) = case.cast::<PyCase>() {
        return Ok(c.borrow().toml.clone());
    }
    if case.cast::<pyo3::types::PyDict>().is_ok() {
        return Ok(PyCase::from_value(case, PathBuf::new())?.toml);
    }
    let text: String = case.str()?.extract()?;
    let path = PathBuf::from(&text);
    if !text.contains('\n') && path.is_file() {
        return tubemem_mesh::io::read_text_limited(&path, tubemem_app::case::MAX_CASE_FILE_BYTES)
            .map_err(|e| PyValueError::new_err(format!("cannot read {}: {e}", path.display())));
    }
    let _ = py;
    Ok(text)
}
