"""`tubemem schema`: the case-file JSON Schema, checked by an independent validator (the
`jsonschema` package, draft 2020-12) against every shipped case, and shown to refuse what
`tubemem run` refuses by key (a misspelt key, a value outside an enumeration, a wrong type)."""

import json
import pathlib
import subprocess
import tomllib

import jsonschema
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHIPPED = sorted((ROOT / "cases").glob("*.toml"))


@pytest.fixture(scope="module")
def validator(tubemem_exe):
    out = subprocess.run([tubemem_exe, "schema"], capture_output=True, text=True, check=True)
    schema = json.loads(out.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_there_are_shipped_cases():
    assert len(SHIPPED) >= 10


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_every_shipped_case_validates(validator, path):
    case = tomllib.loads(path.read_text())
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(case)]
    assert not errors, errors


def _squeeze():
    return tomllib.loads((ROOT / "cases" / "squeeze_abb30_ls1.3.toml").read_text())


def _refused_at(validator, case):
    """The path of the first schema error of `case` (it must have one)."""
    errors = sorted(validator.iter_errors(case), key=lambda e: list(e.absolute_path))
    assert errors, "the schema took a case it should refuse"
    return errors[0]


def test_a_misspelt_key_is_refused_where_it_is(validator):
    case = _squeeze()
    case["mesh"]["arround"] = case["mesh"].pop("around")
    e = _refused_at(validator, case)
    assert list(e.absolute_path) == ["mesh"]
    assert "arround" in e.message


def test_a_misspelt_stage_key_and_a_wrong_value_are_refused(validator, tmp_path, tubemem_exe):
    case = _squeeze()
    case["stage"][1]["target_roh"] = 0.8
    e = _refused_at(validator, case)
    assert list(e.absolute_path) == ["stage", 1]
    assert "target_roh" in e.message

    case = _squeeze()
    case["stage"][1]["contact_method"] = "lagrange"
    e = _refused_at(validator, case)
    assert list(e.absolute_path) == ["stage", 1, "contact_method"]

    case = _squeeze()
    case["geometry"]["radius"] = "one"
    e = _refused_at(validator, case)
    assert list(e.absolute_path) == ["geometry", "radius"]


def test_a_material_key_of_another_law_is_refused(validator):
    case = _squeeze()
    case["material"]["alpha"] = 0.1  # Mooney–Rivlin's parameter on the ABB law
    _refused_at(validator, case)
    case = _squeeze()
    case["material"] = {"model": "yeoh", "c10": 0.5, "c20": 0.01}
    assert not list(validator.iter_errors(case))


def test_a_count_beyond_any_integer_is_refused(validator):
    # JSON Schema's `integer` is any whole number; the schema bounds counts by u64's range,
    # as tubemem does (`around = 1e308` is refused by both)
    case = _squeeze()
    case["mesh"]["around"] = 1e308
    e = _refused_at(validator, case)
    assert list(e.absolute_path) == ["mesh", "around"]


# --- summary.json: `tubemem schema --summary` ----------------------------------------------------


@pytest.fixture(scope="module")
def summary_validator(tubemem_exe):
    out = subprocess.run(
        [tubemem_exe, "schema", "--summary"], capture_output=True, text=True, check=True
    )
    schema = json.loads(out.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("name", ["small_abb30_ls1.2", "channel_abb30_ls1.3"])
def test_a_runs_summary_validates_and_a_damaged_one_is_refused(
    summary_validator, tubemem_exe, tmp_path, name
):
    out = tmp_path / name
    subprocess.run(
        [tubemem_exe, "run", str(ROOT / "cases" / f"{name}.toml"), "--out", str(out)],
        capture_output=True,
        check=True,
    )
    summary = json.loads((out / "summary.json").read_text())
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in summary_validator.iter_errors(summary)]
    assert not errors, errors
    damaged = json.loads(json.dumps(summary))
    damaged["stages"][0]["final"]["w"] = "high"
    assert list(summary_validator.iter_errors(damaged)), "a string for ϖ was taken"
    damaged = json.loads(json.dumps(summary))
    del damaged["stages"]
    assert list(summary_validator.iter_errors(damaged)), "a summary without stages was taken"
