"""Type stubs of the `tubemem` module (PyO3). See the module docstring for units and errors."""

from os import PathLike
from pathlib import Path
from typing import Any, Callable, Iterator, Literal, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class TubememError(RuntimeError):
    """A closed-form solve or finite element run that failed (stage, step and cause)."""

MaterialLike = Optional[Union["Material", Mapping[str, Any]]]
ArrayLike = Union[float, npt.ArrayLike]
Progress = Optional[Union[Callable[[dict], Any], Literal["tqdm"]]]

class Table:
    """Named numpy columns of equal shape (a curve, a vectorized closed form, a run's steps or
    profiles): t["w"], t.columns, len(t), iteration over the names, to_pandas(), to_dict()."""

    def __getitem__(self, key: str) -> np.ndarray: ...
    def __contains__(self, key: str) -> bool: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    @property
    def columns(self) -> list[str]: ...
    def keys(self) -> list[str]: ...
    def to_dict(self) -> dict[str, np.ndarray]: ...
    def to_pandas(self) -> Any: ...

def gps_inflate(
    stretch: ArrayLike, material: MaterialLike = None, hypothesis: str = "gps"
) -> Union[dict[str, float], Table]:
    """Free inflation at hoop stretch λs (eq. 66 GPS, eq. 70 PS): w, lambda_s, lambda_z, n_s, n_z
    (a dict for a number, a Table of arrays of the input's shape for an array)."""

def gps_inflation_curve(
    stretch_to: float,
    points: int = 100,
    stretch_from: float = 1.0,
    material: MaterialLike = None,
    hypothesis: str = "gps",
) -> Table: ...
def gps_flatten(
    initial_stretch: float,
    rho: ArrayLike,
    material: MaterialLike = None,
    hypothesis: str = "gps",
    *,
    control: str = "gas",
    pressure: Optional[float] = None,
) -> Union[dict[str, float], Table]:
    """Squeeze between two plates: control="gas", the gas closed in (eqs. 76–77 GPS, 78–79 PS);
    control="pressure", regulated (eqs. 76 at the inflated pressure held, or ramped to
    `pressure`), with "stiffness": the plates' -d(force)/d(2 rho) at that pressure."""

def gps_between_plates(
    rho: float, w: float, material: MaterialLike = None, hypothesis: str = "gps"
) -> dict[str, float]:
    """Plates at rho < 1 hold the stress-free tube, inflated between them to the pressure w."""

def gps_critical_pressure(
    rho: float, material: MaterialLike = None, hypothesis: str = "gps"
) -> Optional[dict[str, float]]:
    """The first maximum of the pressure along the sections between plates at rho (None: none)."""

def gps_flattening_curve(
    initial_stretch: float,
    rho_to: float,
    points: int = 100,
    material: MaterialLike = None,
    hypothesis: str = "gps",
) -> Table: ...
def gps_section_at_pressure(
    rho: float, w: float, guess: tuple[float, float], material: MaterialLike = None
) -> dict[str, float]:
    """The GPS cross-section at half-gap rho under a given pressure w (eq. 76, no gas law)."""

def gps_limits(material: MaterialLike = None, hypothesis: str = "gps") -> dict[str, Any]: ...
def gps_history(
    prony: Sequence[tuple[float, float]],
    control: str,
    to: float,
    ramp: float = 0.0,
    hold: float = 0.0,
    material: MaterialLike = None,
    hypothesis: str = "gps",
    *,
    plates_to: float | None = None,
    squeeze_time: float = 0.0,
    plates_hold: float = 0.0,
    release: bool = False,
    supply: str = "gas",
    tolerance: float = 1e-10,
    steps: int | None = None,
) -> dict[str, Any]:
    """The GPS section in time with a QLV Prony law (issue #63): a ramp and hold of the
    pressure, stretch or volume, then plates closing, held and released. Keys: history,
    plates (Tables), touch, loop_area, error_estimate, steps_per_segment, g_infinity."""

def resultants(l1: float, l2: float, material: MaterialLike = None) -> tuple[float, float]:
    """Cauchy resultants (N1, N2)/(μH) at principal stretches (eq. 18)."""

def run_case(
    case: Union[str, PathLike],
    out: Union[str, PathLike],
    overwrite: bool = False,
    progress: Progress = None,
) -> dict[str, Any]: ...
def run_case_text(
    text: str,
    out: Union[str, PathLike],
    base_dir: Optional[Union[str, PathLike]] = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> dict[str, Any]: ...
def default_case() -> str: ...

class Case:
    """A validated case: the case file's tables as keywords, a dict, TOML text or a file."""

    def __init__(self, base_dir: Optional[Union[str, PathLike]] = None, **tables: Any) -> None: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any], base_dir: Optional[Union[str, PathLike]] = None) -> "Case": ...
    @staticmethod
    def from_toml(text: str, base_dir: Optional[Union[str, PathLike]] = None) -> "Case": ...
    @staticmethod
    def read(path: Union[str, PathLike]) -> "Case": ...
    def to_toml(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...

class Run:
    """A finished FE run."""

    @property
    def summary(self) -> dict[str, Any]: ...
    @property
    def steps(self) -> Table: ...
    @property
    def profiles(self) -> Table: ...
    @property
    def critical_points(self) -> Table:
        """The located critical points of arc-length stages (critical_points.csv's columns)."""
    @property
    def fronts(self) -> Table:
        """The bulge fronts of every step with a bulge (fronts.csv's columns)."""
    @property
    def path(self) -> Path: ...
    def to_pandas(self) -> Any: ...
    def vtu(self, k: int) -> Path: ...

def run(
    case: Union["Case", str, PathLike, Mapping[str, Any]],
    out: Union[str, PathLike],
    base_dir: Optional[Union[str, PathLike]] = None,
    overwrite: bool = False,
    progress: Progress = None,
) -> Run: ...

def atlas(
    atlas: Union[str, PathLike],
    out: Union[str, PathLike],
    client: Any = None,
    workers: Optional[int] = None,
    progress: Optional[Callable[[dict[str, Any]], Any]] = None,
) -> Any:
    """Run an atlas file (one FE run per λs* and L/R; locally on `workers` threads, or on a Dask
    client, bit for bit the same) into `out`, fit the end-effect laws, and return an xarray
    Dataset: error_<q>, fe_<q>, gps_<q> over (lambda_s_star, rho, length_ratio);
    min_length_ratio_<q> over (lambda_s_star, rho, epsilon); c_<q>, a_<q>, fit_residual_<q>,
    flag_<q> over (lambda_s_star, rho). Also written as out/atlas.nc. `progress`: a callable
    given {"member", "done", "total", "error"} per finished member."""

def _atlas_member(atlas_text: str, base_dir: str, index: int, dir: str) -> str: ...

def sweep(
    cases: list,
    out: Union[str, PathLike],
    params: Optional[list[Mapping[str, Any]]] = None,
    client: Any = None,
    workers: Optional[int] = None,
    progress: Union[None, str, Callable[[dict[str, Any]], Any]] = None,
    processes: Optional[int] = None,
) -> Any:
    """Run many cases (locally on `workers` threads of this process, or on a Dask client); a
    pandas DataFrame with one row per case and converged step; failed members keep their
    `error` and lose no others. `processes` is the former name of `workers`. `progress`:
    "tqdm", or a callable given {"case", "done", "total", "error"} per finished member."""

def _sweep_one(index: int, text: str, out: Union[str, PathLike]) -> dict[str, Any]: ...

def verify(
    suites: Optional[list[Union[str, PathLike]]] = None,
    out: Union[str, PathLike] = "tubemem-verify",
    case: Optional[Union[str, PathLike]] = None,
    quick: bool = False,
    jobs: Optional[int] = None,
    filter: Optional[str] = None,
    update_gold: bool = False,
    python: Optional[Union[str, PathLike]] = None,
    python_ref: Optional[Union[str, PathLike]] = None,
    epsilon: Optional[float] = None,
) -> dict[str, Any]:
    """Verification suites (or the study of one case, with `epsilon` the accuracy asked for,
    default 1e-3): results.json's content as a dict."""


class Material:
    """A membrane law, validated on construction: Material("gent", shear_modulus=1.0, jm=50),
    Material(model="invariants", energy="-(jm/2)*ln(1-(I1-3)/jm)", parameters={"jm": 50},
    shear_modulus=1.0), or Material.from_dict(a case file's material table). The models:
    abb, mooney-rivlin, neo-hookean, yeoh, gent, gent-gent, arruda-boyce, ogden,
    saint-venant-kirchhoff (svk), invariants (an energy of I1, I2 as text), principal (w(l) as
    text, W = w(λ1) + w(λ2) + w(λ3)). A bad law raises ValueError naming the parameter or the
    energy's column."""

    def __init__(self, model: Optional[str] = None, **params: Any) -> None: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> "Material": ...
    def to_dict(self) -> dict[str, Any]: ...
    @property
    def name(self) -> str: ...
    @property
    def shear_modulus(self) -> float: ...
    def resultants(self, l1: float, l2: float) -> tuple[float, float]: ...
    def energy(self, l1: float, l2: float) -> float: ...
    def nominal_stress(
        self, mode: Literal["uniaxial", "equibiaxial", "pure_shear"], stretch: ArrayLike
    ) -> np.ndarray: ...

TestData = Union[str, PathLike, npt.ArrayLike, tuple[npt.ArrayLike, npt.ArrayLike]]

def fit(
    law: Union[str, "Material", Mapping[str, Any]],
    uniaxial: Optional[TestData] = None,
    equibiaxial: Optional[TestData] = None,
    pure_shear: Optional[TestData] = None,
    fix: Optional[Mapping[str, float]] = None,
    bounds: Optional[Mapping[str, tuple[float, float]]] = None,
    starts: Optional[int] = None,
) -> dict[str, Any]:
    """Fit a law's parameters to test data (nominal stress against stretch; CSV paths whose
    headers name the stress unit, read in Pa, (N, 2) arrays or (stretch, stress) pairs):
    material (the fitted Material), converged and stop_reason, parameters (name, value,
    std_error — None where fixed or not determined —, determined, fixed, at_bound),
    correlation, rank, residual_std, stress_unit, warnings, …"""
