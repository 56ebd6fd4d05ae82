"""Type stubs of the Rust extension (aeromag._aeromag). Units: nT, degrees,
m, s; rows are the file's data rows, 0-based."""

from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union, final

import os

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "__version__",
    "Grid",
    "Microlevelled",
    "grid_flight",
    "microlevel",
    "read_grid",
    "_grid_from_state",
    "_microlevelled_from_state",
    "Flight",
    "read_flight",
    "_flight_from_state",
    "TlModel",
    "OnlineCompensator",
    "calibrate",
    "check_calibrate_options",
    "calibrate_defaults",
    "load_model",
    "_model_from_json",
    "observability",
    "SensorsModel",
    "calibrate_sensors",
    "Model",
    "fit_rotor",
    "fit_pod",
    "locate_dipole",
    "dipole_crlb",
    "simulate_gradiometer",
    "EmDetection",
    "EmCalibration",
    "EmPoses",
    "simulate_em",
    "detect_em",
    "calibrate_em",
    "_em_calibration_from_json",
    "_em_detection_from_state",
    "_em_poses_from_state",
    "locate_em",
    "Levelled",
    "_levelled_from_state",
    "level",
    "score",
    "igrf",
    "decimal_year",
    "simulate",
]

_Labels = Union[None, str, float, Sequence[Union[str, float]]]
_ColumnMapLike = Union[None, str, Mapping[str, str]]
_Progress = Optional[Callable[[str, int, int], Any]]

@final
class Flight:
    """A flight record: named columns of equal length, canonical names
    (time, mag, flux_x, …) mapped onto the file's names."""

    @staticmethod
    def from_dict(
        data: Mapping[str, Any],
        columns: _ColumnMapLike = None,
        mag: Optional[str] = None,
        vector: Optional[str] = None,
        lines: _Labels = None,
        time_range: Optional[Tuple[float, float]] = None,
        copy: bool = True,
    ) -> "Flight": ...
    @staticmethod
    def from_pandas(
        df: Any,
        columns: _ColumnMapLike = None,
        mag: Optional[str] = None,
        vector: Optional[str] = None,
        lines: _Labels = None,
        time_range: Optional[Tuple[float, float]] = None,
        copy: bool = True,
    ) -> "Flight": ...
    def to_dict(self) -> Dict[str, np.ndarray]: ...
    def to_csv(self, path: str) -> None: ...
    def to_xyz(self, path: str) -> None: ...
    def to_hdf5(self, path: str) -> None: ...
    def to_mat(self, path: str) -> None: ...
    def to_pandas(self) -> Any: ...
    def to_polars(self) -> Any: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...
    def __len__(self) -> int: ...
    def __getitem__(self, name: str, /) -> np.ndarray: ...
    def __contains__(self, name: str, /) -> bool: ...
    @property
    def columns(self) -> List[str]: ...
    @property
    def unread_columns(self) -> List[str]: ...
    @property
    def not_read(self) -> List[Tuple[str, str]]: ...
    @property
    def mapping(self) -> List[Tuple[str, str]]: ...
    @property
    def file(self) -> Optional[str]: ...
    @property
    def warnings(self) -> List[str]: ...

@final
class TlModel:
    """A fitted Tolles-Lawson model (the model file of `aeromag calibrate`)."""

    @property
    def coef(self) -> npt.NDArray[np.float64]: ...
    @property
    def coef_std(self) -> npt.NDArray[np.float64]: ...
    @property
    def terms(self) -> List[str]: ...
    @property
    def method(self) -> str: ...
    @property
    def notes(self) -> List[str]: ...
    @property
    def fit_stats(self) -> Dict[str, float]: ...
    @property
    def series(self) -> Optional[Dict[str, npt.NDArray[np.float64]]]: ...
    def interference(self, flight: Flight) -> npt.NDArray[np.float64]: ...
    def compensate(
        self, flight: Flight, causal: bool = False, sample_rate: Optional[float] = None
    ) -> npt.NDArray[np.float64]: ...
    def online(
        self, sample_rate: Optional[float] = None, adapt: Optional[str] = None
    ) -> OnlineCompensator: ...
    def apply(self, flight: Flight) -> Flight: ...
    def to_json(self) -> str: ...
    def save(self, path: str) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

@final
class OnlineCompensator:
    """A Tolles-Lawson model compensating samples as they arrive (latency 0)."""

    def __new__(
        cls, model: TlModel, sample_rate: Optional[float] = None, adapt: Optional[str] = None
    ) -> OnlineCompensator: ...
    @property
    def coefficients(self) -> Optional[Dict[str, Any]]: ...
    @property
    def outliers(self) -> Optional[int]: ...
    @property
    def channels(self) -> List[str]: ...
    @property
    def max_step_s(self) -> float: ...
    def push(
        self,
        time: float,
        flux: Tuple[float, float, float],
        mag: float,
        channels: Sequence[float] = ...,
        speed: float = ...,
        alt: float = ...,
    ) -> Tuple[float, float, int]: ...
    def push_block(
        self,
        time: npt.NDArray[np.float64],
        flux_x: npt.NDArray[np.float64],
        flux_y: npt.NDArray[np.float64],
        flux_z: npt.NDArray[np.float64],
        mag: npt.NDArray[np.float64],
        channels: Union[None, Sequence[npt.NDArray[np.float64]], Mapping[str, npt.NDArray[np.float64]]] = None,
        speed: Optional[npt.NDArray[np.float64]] = None,
        alt: Optional[npt.NDArray[np.float64]] = None,
    ) -> Dict[str, npt.NDArray[Any]]: ...
    def reset(self) -> None: ...

@final
class SensorsModel:
    """One Tolles-Lawson model per scalar sensor (`aeromag calibrate --mag A,B,…`)."""

    @property
    def sensors(self) -> List[str]: ...
    @property
    def columns(self) -> List[str]: ...
    @property
    def reference_sensors(self) -> List[Optional[str]]: ...
    @property
    def models(self) -> List[TlModel]: ...
    @property
    def notes(self) -> List[str]: ...
    def compensate(self, flight: Flight) -> Dict[str, npt.NDArray[np.float64]]: ...
    def apply(self, flight: Flight) -> Flight: ...
    def score(self, flight: Flight, reference: Optional[str] = None) -> Dict[str, Any]: ...
    def to_json(self) -> str: ...
    def save(self, path: str) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...
    def __len__(self) -> int: ...

def calibrate_sensors(
    flight: Flight,
    mag: Sequence[str],
    params: Mapping[str, Any],
    vector: Optional[Sequence[str]] = None,
    reference_sensor: Optional[str] = None,
    progress: _Progress = None,
) -> SensorsModel: ...
def read_flight(
    path: str,
    columns: _ColumnMapLike = None,
    mag: Optional[str] = None,
    vector: Optional[str] = None,
    lines: _Labels = None,
    time_range: Optional[Tuple[float, float]] = None,
    fields: Optional[List[str]] = None,
) -> Flight: ...
def _flight_from_state(layout: str, numbers: bytes) -> Flight:
    """Rebuild a pickled flight (``Flight.__reduce__``)."""
def calibrate(flight: Flight, params: Mapping[str, Any], progress: _Progress = None) -> TlModel: ...
def check_calibrate_options(params: Mapping[str, Any]) -> None: ...
def calibrate_defaults() -> Dict[str, Any]: ...
def load_model(path: str) -> Union[TlModel, SensorsModel, "Model"]: ...
def _model_from_json(
    text: str, notes: str = "[]", series: Optional[bytes] = None
) -> Union[TlModel, SensorsModel, "Model"]:
    """Rebuild a pickled model (the models' ``__reduce__``)."""
def decimal_year(date: str) -> float: ...
def igrf(
    lat_deg: npt.NDArray[np.float64],
    lon_deg: npt.NDArray[np.float64],
    alt_m: npt.NDArray[np.float64],
    decimal_year: npt.NDArray[np.float64],
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def simulate(
    scenario: str,
    seed: Optional[int] = None,
    config: Optional[str] = None,
    config_path: Optional[str] = None,
) -> Flight: ...

@final
class Model:
    """A fitted helicopter-rotor or towed-pod model (`aeromag rotor fit`, `aeromag pod fit`)."""

    @property
    def kind(self) -> str: ...
    @property
    def coef(self) -> npt.NDArray[np.float64]: ...
    @property
    def notes(self) -> List[str]: ...
    def interference(self, flight: Flight) -> npt.NDArray[np.float64]: ...
    def compensate(self, flight: Flight) -> npt.NDArray[np.float64]: ...
    def apply(self, flight: Flight) -> Flight: ...
    def heading_rates(self, flight: Flight) -> List[Tuple[float, int, int, float]]: ...
    def to_json(self) -> str: ...
    def save(self, path: str) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

@final
class Levelled:
    """A levelled survey (`aeromag level`)."""

    @property
    def value_column(self) -> str: ...
    @property
    def output_column(self) -> str: ...
    @property
    def levelled(self) -> npt.NDArray[np.float64]: ...
    @property
    def flags(self) -> npt.NDArray[np.float64]: ...
    @property
    def k_s(self) -> Tuple[float, float]: ...
    @property
    def rms_nt(self) -> Dict[str, float]: ...
    @property
    def line_levels(self) -> List[Tuple[str, int, float, float, float, float]]: ...
    @property
    def notes(self) -> List[str]: ...
    def crossovers(self) -> Flight: ...
    def to_flight(self) -> Flight: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

def _levelled_from_state(state: bytes, flight: Flight) -> Levelled:
    """Rebuild a pickled levelled survey (``Levelled.__reduce__``)."""

def fit_rotor(
    flight: Flight,
    preset: Optional[str] = None,
    hub_m: Optional[Tuple[float, float, float]] = None,
    sensor_m: Optional[Tuple[float, float, float]] = None,
    blade_span_m: Optional[Tuple[float, float]] = None,
    blades: Optional[int] = None,
    coning_deg: Optional[float] = None,
    tilt_lon_deg: Optional[float] = None,
    phase_column: Optional[str] = None,
    estimate_phase: bool = False,
    rotor_hz: Optional[Tuple[float, float]] = None,
    window_s: Optional[float] = None,
    tail_rotor: bool = False,
    tail_hub_m: Optional[Tuple[float, float, float]] = None,
    tail_spin_axis: Optional[Tuple[float, float, float]] = None,
    tail_zero_azimuth: Optional[Tuple[float, float, float]] = None,
    tail_blade_span_m: Optional[Tuple[float, float]] = None,
    tail_blades: Optional[int] = None,
    gear_ratio: Optional[float] = None,
    progress: _Progress = None,
) -> Model: ...
def fit_pod(
    flight: Flight,
    cable_length_m: float,
    inclination_deg: float,
    attach_m: Optional[Tuple[float, float, float]] = None,
    declination_deg: float = 0.0,
    grad_north_nt_per_km: float = 0.0,
    grad_up_nt_per_km: float = 0.0,
    method: str = "dipole-array",
    source_points: Optional[Sequence[Tuple[float, float, float]]] = None,
    progress: _Progress = None,
) -> Model: ...
def level(
    flight: Flight,
    value: Optional[str] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    rate_of: Optional[str] = None,
    tie_only: bool = False,
    drift: bool = False,
    no_altitude_term: bool = False,
    no_robust: bool = False,
    ridge_lambda: Optional[float] = None,
    reference: Union[None, str, Sequence[str]] = None,
    ties: Optional[Sequence[str]] = None,
    xy: Optional[Tuple[str, str]] = None,
    utm_zone: Optional[str] = None,
    progress: _Progress = None,
) -> Levelled: ...
@final
class Grid:
    """A grid (`aeromag grid`): node values, coordinates, CRS."""

    @property
    def values(self) -> npt.NDArray[np.float64]: ...
    @property
    def x(self) -> npt.NDArray[np.float64]: ...
    @property
    def y(self) -> npt.NDArray[np.float64]: ...
    @property
    def cell(self) -> float: ...
    @property
    def epsg(self) -> Optional[int]: ...
    @property
    def crs(self) -> Optional[str]: ...
    @property
    def name(self) -> str: ...
    @property
    def unit(self) -> str: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    def stats(self) -> Dict[str, float]: ...
    def sample(self, x: float, y: float) -> float: ...
    def vertical_derivative(self) -> Grid: ...
    def upward(self, height_m: float) -> Grid: ...
    def minus(self, other: Grid) -> Grid: ...
    @staticmethod
    def from_array(
        values: npt.ArrayLike,
        x: npt.ArrayLike,
        y: npt.ArrayLike,
        *,
        name: str = "",
        unit: str = "",
        epsg: Optional[int] = None,
    ) -> Grid: ...
    def to_xarray(self) -> Any: ...
    @staticmethod
    def from_xarray(array: Any, *, epsg: Optional[int] = None) -> Grid: ...
    def write(self, path: Union[str, "os.PathLike[str]"]) -> None: ...
    def write_map(self, path: Union[str, "os.PathLike[str]"], diverging: bool = False) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

@final
class Microlevelled:
    """A micro-levelled survey (`aeromag microlevel`)."""

    @property
    def column(self) -> str: ...
    @property
    def output_column(self) -> str: ...
    @property
    def values(self) -> npt.NDArray[np.float64]: ...
    @property
    def correction(self) -> npt.NDArray[np.float64]: ...
    @property
    def correction_nt(self) -> Tuple[float, float]: ...
    @property
    def crossover_rms_nt(self) -> Optional[Tuple[float, float]]: ...
    @property
    def gridding(self) -> Tuple[int, bool]: ...
    @property
    def notes(self) -> List[str]: ...
    def to_flight(self) -> Flight: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

def _microlevelled_from_state(state: bytes, flight: Flight) -> Microlevelled:
    """Rebuild a pickled micro-levelled survey (``Microlevelled.__reduce__``)."""

def grid_flight(
    flight: Flight,
    column: Optional[str] = None,
    cell: Optional[float] = None,
    tension: float = 0.25,
    method: str = "min-curvature",
    blanking: Optional[float] = None,
    utm_zone: Optional[str] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    extent: Optional[Tuple[float, float, float, float]] = None,
    max_sweeps: int = 500,
    convergence: Optional[float] = None,
    xy: Optional[Tuple[str, str]] = None,
    progress: _Progress = None,
) -> Grid: ...
def read_grid(path: Union[str, "os.PathLike[str]"]) -> Grid: ...
def _grid_from_state(
    values: bytes,
    geometry: Tuple[float, float, float, int, int],
    epsg: Optional[int],
    name: str,
    unit: str,
    info: Dict[str, Any],
) -> Grid:
    """Rebuild a pickled grid (``Grid.__reduce__``)."""
def microlevel(
    flight: Flight,
    column: Optional[str] = None,
    cell: Optional[float] = None,
    cutoff: float = 4.0,
    along_line: Optional[float] = None,
    cosine_power: float = 2.0,
    tension: float = 0.25,
    utm_zone: Optional[str] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    max_sweeps: int = 500,
    convergence: Optional[float] = None,
    xy: Optional[Tuple[str, str]] = None,
    progress: _Progress = None,
) -> Microlevelled: ...
def score(
    flight: Flight,
    reference: Union[None, str, Sequence[str]] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    decimal_year: Optional[float] = None,
) -> str: ...
def observability(
    flight: Flight,
    terms: Optional[str] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    decimal_year: Optional[float] = None,
    progress: _Progress = None,
) -> str: ...
def locate_dipole(
    flight: Flight,
    config: Optional[str] = None,
    gradiometer: Optional[str] = None,
    layout: Optional[str] = None,
    baseline_m: Optional[float] = None,
    noise_nt: Optional[float] = None,
    passes: Optional[int] = None,
    multistart: Optional[bool] = None,
) -> Flight: ...
def dipole_crlb(config: Optional[str] = None) -> str: ...
def simulate_gradiometer(config: Optional[str] = None, seed: Optional[int] = None) -> Flight: ...
@final
class EmDetection:
    """Detected complex field vectors of a raw EM record (T)."""

    @property
    def sample_rate_hz(self) -> float: ...
    @property
    def window_len(self) -> int: ...
    @property
    def polarization_ratio_rms(self) -> float: ...
    @property
    def notes(self) -> List[str]: ...
    def __len__(self) -> int: ...
    def to_dict(self) -> Dict[str, np.ndarray]: ...
    def save(self, path: str) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

@final
class EmCalibration:
    """The three calibration stages of an EM positioning system."""

    @property
    def polarization_ratio_before(self) -> float: ...
    @property
    def polarization_ratio_after(self) -> float: ...
    @property
    def transmitter_distortion(self) -> float: ...
    @property
    def attitude_correction_deg(self) -> float: ...
    def to_json(self) -> str: ...
    def save(self, path: str) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

@final
class EmPoses:
    """The pose of the towed bird at every epoch (m, deg)."""

    @property
    def failed(self) -> int: ...
    @property
    def by_continuity(self) -> int: ...
    @property
    def notes(self) -> List[str]: ...
    def __len__(self) -> int: ...
    def to_dict(self) -> Dict[str, np.ndarray]: ...
    def save(self, path: str) -> None: ...
    def __reduce__(self) -> Tuple[Callable[..., Any], Tuple[Any, ...]]: ...

def simulate_em(
    out: str, config: Optional[str] = None, seed: Optional[int] = None, known_positions: int = 8
) -> Dict[str, Any]: ...
def detect_em(
    raw: str,
    window_len: Optional[int] = None,
    window: str = "blackman-harris",
    pilot: bool = True,
    system: Optional[str] = None,
    progress: _Progress = None,
) -> EmDetection: ...
def calibrate_em(
    detected: Union[EmDetection, str],
    known: str,
    system: str,
    half_space: Sequence[float] = (-1.0, 0.0, 1.0),
) -> EmCalibration: ...
def _em_calibration_from_json(
    text: str,
    polarization_ratio_before: float,
    polarization_ratio_after: float,
    transmitter_distortion: float,
    attitude_correction_deg: float,
) -> EmCalibration:
    """Rebuild a pickled EM calibration (``EmCalibration.__reduce__``)."""
def _em_detection_from_state(state: bytes) -> EmDetection:
    """Rebuild a pickled EM detection (``EmDetection.__reduce__``)."""
def _em_poses_from_state(state: bytes) -> EmPoses:
    """Rebuild pickled EM poses (``EmPoses.__reduce__``)."""
def locate_em(
    detected: Union[EmDetection, str],
    calibration: Union[EmCalibration, str],
    half_space: Sequence[float] = (-1.0, 0.0, 1.0),
    progress: _Progress = None,
) -> EmPoses: ...
