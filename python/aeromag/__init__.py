"""aeromag: magnetic and low-frequency EM measurements from moving platforms.

The Python face of the aeromag Rust library: the same code as the
``aeromag`` command line, with NumPy arrays in and out.

Quick start (see ``examples/quickstart.py``)::

    import aeromag
    cal = aeromag.simulate("calibration", seed=1)       # or aeromag.read_flight("cal.h5", lines="1002.02")
    tl = aeromag.TollesLawson(method="ls").fit(cal)
    tl.coef_, tl.coef_std_, tl.terms_                      # fitted coefficients
    survey = aeromag.simulate("survey", seed=2)
    compensated = tl.transform(survey)                     # nT, NaN where not computable
    tl.save("model.json")                                  # the CLI's model file

Units: magnetic values in nT, positions in degrees and m (WGS84 ellipsoidal
height), attitude in degrees, time in s. Files keep their own names
(``mag_1_uc``, ``INS_LAT`` …); the canonical names (``time``, ``mag``,
``flux_x`` …) are mapped onto them as the CLI maps them.

Errors: :class:`BadInputError` (a ``ValueError``, with ``file``, ``line``,
``row``, ``column``) for input that cannot be used (:class:`MissingFileError`,
also a ``FileNotFoundError``, for an input file that does not exist),
:class:`AeromagError` for methods that failed, ``OSError`` for outputs that
could not be written.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _aeromag
from ._aeromag import EmCalibration, EmDetection, EmPoses, calibrate_em, simulate_em
from ._aeromag import Grid, Microlevelled
from ._aeromag import Flight, Levelled, Model, OnlineCompensator, SensorsModel, TlModel, fit_pod, fit_rotor, locate_dipole, simulate_gradiometer
from ._aeromag import __version__
from .errors import AeromagError, AeromagWarning, BadInputError, MissingFileError
from .tolles_lawson import TollesLawson, calibrate_sensors, load_model

__all__ = [
    "AeromagError",
    "AeromagWarning",
    "BadInputError",
    "MissingFileError",
    "Flight",
    "Levelled",
    "Model",
    "Grid",
    "Microlevelled",
    "grid_flight",
    "microlevel",
    "read_grid",
    "fit_pod",
    "fit_rotor",
    "dipole_crlb",
    "locate_dipole",
    "simulate_gradiometer",
    "EmCalibration",
    "EmDetection",
    "EmPoses",
    "calibrate_em",
    "detect_em",
    "locate_em",
    "simulate_em",
    "level",
    "observability",
    "score",
    "OnlineCompensator",
    "SensorsModel",
    "TlModel",
    "TollesLawson",
    "calibrate_sensors",
    "decimal_year",
    "igrf",
    "load_model",
    "read_flight",
    "simulate",
    "__version__",
    "batch",
]


def __dir__() -> List[str]:
    """The package's API and its modules (``dir(aeromag)``, tab completion),
    without the names its own code imports (``np``, ``os``, ``Optional`` …)."""
    return sorted(set(__all__) | {"errors", "tolles_lawson"})


PathLike = Union[str, "os.PathLike[str]"]


def read_flight(
    path: PathLike,
    columns: Union[None, str, Mapping[str, str]] = None,
    mag: Optional[str] = None,
    vector: Optional[str] = None,
    lines: Union[None, str, float, Iterable[Any]] = None,
    time_range: Optional[Tuple[float, float]] = None,
    fields: Union[None, str, Iterable[str]] = None,
) -> Flight:
    """Read a flight file: CSV, Geosoft XYZ, HDF5 (MagNav/SGL layout) or a
    MATLAB MAT-file (v5/v7, and v7.3 which is HDF5): its numeric vectors at
    the top level, or the fields of its one struct, or of MagNav.jl's
    ``traj`` and ``ins_data`` structs (``ins_data.lat`` → ``ins_lat``).
    ``Flight.not_read`` lists what else the file holds (scalars, matrices,
    text).

    Parameters are the CLI's reading options:

    - ``columns``: canonical name → the file's column, as a dict
      (``{"mag": "mag_1_uc"}``) or the CLI's text (``"mag=mag_1_uc"``);
      MagNav/SGL and Geosoft XYZ names are recognised without it;
    - ``mag``: the scalar magnetometer (``"mag_3_uc"``; XYZ's
      ``UNCOMPMAG3`` is found by that name too);
    - ``vector``: the vector magnetometer by prefix (``"flux_b"``);
    - ``lines``: keep only the rows on these line labels (``"1002.02"``,
      ``[1003.01, 1003.02]``, ``"L1020,T901"``);
    - ``time_range``: keep only the rows with ``t0 ≤ time ≤ t1`` (s);
    - ``fields``: read only these fields (default: every one): file names,
      canonical names (through the map, the preset or a derivation: ``lat``
      brings ``ins_lat``), ``true_*`` by prefix and ``*_level`` by suffix,
      without regard to case; the ``line`` and ``time`` a row selection
      needs are added. An HDF5 file then reads only those datasets and a
      text file parses only those fields: less time and memory for a wide
      file. ``Flight.unread_columns`` lists the others.

    Raises :class:`BadInputError` naming file, line, row and column.
    """
    if isinstance(fields, str):
        fields = [fields]
    return _aeromag.read_flight(
        os.fspath(path),
        columns=columns,
        mag=mag,
        vector=vector,
        lines=lines,
        time_range=time_range,
        fields=None if fields is None else list(fields),
    )


def decimal_year(date: str) -> float:
    """The decimal year of a date ``YYYY-MM-DD`` (``2025-07-02`` → 2025.5)."""
    return _aeromag.decimal_year(date)


def _real_array(name: str, value: Any) -> np.ndarray:
    """``value`` as float64, a TypeError naming ``name`` for None (read as
    NaN: "lat NaN°") or complex values (their imaginary part was dropped
    with NumPy's warning only)."""
    if value is None:
        raise TypeError(f"{name} must be a number or an array of numbers, not None")
    a = np.asarray(value)
    if np.iscomplexobj(a):
        raise TypeError(f"{name} must be real numbers, not complex")
    try:
        return a.astype(np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be numbers: {e}") from None


def igrf(
    lat: Any, lon: Any, alt: Any = 0.0, time: Union[str, float, Any] = "2025-01-01"
) -> Dict[str, np.ndarray]:
    """The IGRF-14 main field at geodetic points, vectorised.

    ``lat``, ``lon`` in degrees, ``alt`` in m above the WGS84 ellipsoid,
    ``time`` a date ``"YYYY-MM-DD"``, a decimal year, or an array of
    decimal years; arrays broadcast against each other (NumPy rules).

    Returns a dict of arrays of the broadcast shape: ``x`` (north), ``y``
    (east), ``z`` (down), ``f`` (total) in nT, ``declination`` and
    ``inclination`` in degrees.
    """
    if isinstance(time, str):
        time = decimal_year(time)
    la, lo, al, ti = np.broadcast_arrays(
        *(_real_array(n, v) for n, v in (("lat", lat), ("lon", lon), ("alt", alt), ("time", time)))
    )
    shape = la.shape
    flat = [np.ascontiguousarray(a).reshape(-1) for a in (la, lo, al, ti)]
    x, y, z = _aeromag.igrf(*flat)
    h = np.hypot(x, y)
    out = {
        "x": x,
        "y": y,
        "z": z,
        "f": np.hypot(h, z),
        "declination": np.degrees(np.arctan2(y, x)),
        "inclination": np.degrees(np.arctan2(z, h)),
    }
    return {k: v.reshape(shape) for k, v in out.items()}


def simulate(
    scenario: str, seed: Optional[int] = None, config: Union[None, str, PathLike] = None
) -> Flight:
    """Simulate a flight with truth (``aeromag simulate``).

    ``scenario``: ``"calibration"``, ``"calibration_truncated"``,
    ``"survey"``, ``"helicopter"`` or ``"pod"``; ``seed`` the random seed
    (the scenario's default when None); ``config`` a scenario file (TOML)
    by path, or its text. The flight carries ``true_…`` columns (truth:
    estimators never read them).
    """
    text = None
    if config is not None:
        path = os.fspath(config)
        if os.path.isfile(path):
            return _aeromag.simulate(scenario, seed=seed, config_path=path)
        elif isinstance(config, str) and ("\n" in config or "=" in config or not config.strip()):
            text = config
        else:
            # A path that names no file was parsed as TOML text ("expected
            # `.`, `=`"): say which file is missing.
            raise MissingFileError(
                f"config: no file {path!r} (config is a scenario file's path or its TOML text)",
                file=path,
            )
    return _aeromag.simulate(scenario, seed=seed, config=text)


def _year(date: Union[None, str, float]) -> Optional[float]:
    return decimal_year(date) if isinstance(date, str) else date


def score(
    flight: Flight,
    reference: Union[None, str, Sequence[str]] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    date: Union[None, str, float] = None,
) -> Dict[str, Any]:
    """The figures of a compensated flight (``aeromag report``'s figures.json).

    ``flight`` must have ``mag_comp`` (``model.apply(flight)`` adds it).
    ``reference``: external-field channels removed before the FOM and IR
    (None/``"auto"``: ``diurnal`` and ``igrf`` when present; ``"none"``; a
    list). Returns ``fom_before_nt``, ``fom_after_nt``, ``fom_windows``,
    ``ir`` (None with a reason when they cannot be computed), and for
    simulated flights ``residual_rms_nt``, ``interference_rms_nt``,
    ``noise_floor_nt`` and per-line residuals.
    """
    import json

    return json.loads(_aeromag.score(flight, reference=reference, lever_arm=lever_arm, decimal_year=_year(date)))


def observability(
    flight: Flight,
    terms: Optional[str] = None,
    lever_arm: Optional[Tuple[float, float, float]] = None,
    date: Union[None, str, float] = None,
    progress: Any = None,
) -> Dict[str, Any]:
    """What a calibration flight determines (``aeromag observability``).

    Returns ``rank``, ``condition``, ``eigenvalues``, ``weak_combinations``,
    ``undetermined`` (term names) and ``coefficients``: per term ``name``,
    ``mu`` (estimability: 0 determined by the flight, 1 left at its prior),
    ``std``, ``effect_std_nt`` and ``verdict``.
    """
    import json

    from .tolles_lawson import progress_callback

    return json.loads(
        _aeromag.observability(
            flight, terms=terms, lever_arm=lever_arm, decimal_year=_year(date), progress=progress_callback(progress)
        )
    )


def detect_em(
    raw: PathLike,
    window_len: Optional[int] = None,
    window: str = "blackman-harris",
    pilot: bool = True,
    system: Optional[PathLike] = None,
    progress: Any = None,
) -> EmDetection:
    """Detect the complex field vectors of a raw EM record (``aeromag em detect``).

    Synchronous detection in blocks of ``window_len`` samples (default the
    library's) weighted by ``window`` (``"blackman-harris"`` or
    ``"nuttall"``), divided by the pilot-measured channel sensitivity
    (``pilot=False`` shows the drift); instrument constants from the raw
    header or ``system`` (JSON). Returns an :class:`EmDetection`:
    ``len()`` epochs, ``to_dict()`` (``time_s`` in s, fields
    ``h{i}_{x,y,z}_{re,im}_t`` in T, ``pol_ratio_{i}``), ``save(path)``
    (the CLI's CSV), ``polarization_ratio_rms``, ``notes``.
    """
    from .tolles_lawson import progress_callback

    return _aeromag.detect_em(
        os.fspath(raw),
        window_len=window_len,
        window=window,
        pilot=pilot,
        system=None if system is None else os.fspath(system),
        progress=progress_callback(progress),
    )


def locate_em(
    detected: Union[EmDetection, PathLike],
    calibration: Union[EmCalibration, PathLike],
    half_space: Tuple[float, float, float] = (-1.0, 0.0, 1.0),
    progress: Any = None,
) -> EmPoses:
    """Locate the towed bird at every epoch (``aeromag em locate``).

    ``detected``: an :class:`EmDetection` or a detected-vector CSV;
    ``calibration``: an :class:`EmCalibration` or a calibration file;
    ``half_space``: the normal n of the prior half-space r·n > 0
    (transmitter frame, default behind and below). Returns
    :class:`EmPoses`: ``to_dict()`` with ``x_m, y_m, z_m`` (m, transmitter
    frame), ``range_m``, ``roll_deg, pitch_deg, yaw_deg`` (Z-Y-X, deg),
    quality figures and ``status``; ``save(path)`` (the CLI's CSV);
    ``failed``.
    """
    from .tolles_lawson import progress_callback

    if not isinstance(detected, EmDetection):
        detected = os.fspath(detected)
    if not isinstance(calibration, EmCalibration):
        calibration = os.fspath(calibration)
    return _aeromag.locate_em(detected, calibration, half_space=half_space, progress=progress_callback(progress))


def _labels(x: Any) -> Optional[List[str]]:
    """Line labels from a label, a comma-separated text or a sequence
    (``"2001"`` is one label, not the characters 2, 0, 0, 1)."""
    if x is None:
        return None
    if isinstance(x, (str, bytes)):
        text = x.decode() if isinstance(x, bytes) else x
        return [t.strip() for t in text.split(",") if t.strip()]
    if isinstance(x, (int, float)):
        return [str(x)]
    return [str(t) for t in x]


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
    progress: Any = None,
) -> Levelled:
    """Level a survey at its line/tie-line crossovers (``aeromag level``).

    The keywords are the command's flags (``--lambda`` → ``ridge_lambda``):
    ``value`` the column to level (default the compensated reading,
    any case: ``mag_comp``, else the first ``mag_<k>_comp``; else ``mag``
    with the warning ``[uncompensated-default]``),
    ``lever_arm`` the sensor's position (m, body frame), ``rate_of`` the
    column whose derivative is the ``k·d|B0|/dt`` regressor, ``tie_only``
    classic tie-line levelling, ``drift`` a linear drift per line,
    ``reference`` channels removed first (default none), ``ties`` the tie
    line labels when neither ``line_type`` nor ``L``/``T`` labels say,
    ``xy`` the columns ``(easting, northing)`` of positions already
    projected (m; default ``lat``/``lon``, or in a flight without them the
    first of ``x``/``y``, ``easting``/``northing``, ``utm_x``/``utm_y``,
    ``utm-x``/``utm-y``, ``utm_easting``/``utm_northing``, any case), UTM coordinates of the zone
    ``utm_zone`` (``"37N"``), which they need.

    Returns a :class:`Levelled`: ``levelled`` (nT), ``flags``, ``k_s``
    (k, σ in s), ``rms_nt``, ``line_levels``, ``crossovers()`` (the
    crossover table as a Flight), ``to_flight()``.
    """
    from .tolles_lawson import progress_callback

    return _aeromag.level(
        flight,
        value=value,
        lever_arm=lever_arm,
        rate_of=rate_of,
        tie_only=tie_only,
        drift=drift,
        no_altitude_term=no_altitude_term,
        no_robust=no_robust,
        ridge_lambda=ridge_lambda,
        reference=reference,
        ties=_labels(ties),
        xy=xy,
        utm_zone=utm_zone,
        progress=progress_callback(progress),
    )


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
    progress: Any = None,
) -> Grid:
    """Grid a column of a survey (``aeromag grid``).

    Rows on lines are projected to UTM (``utm_zone`` such as ``"37N"`` or
    ``"EPSG:32637"``, default the data's zone; at the sensor with
    ``lever_arm``) and gridded by minimum curvature with ``tension``
    (``method="bidirectional"``: along the lines, then across them).
    Defaults follow the lines: ``column`` the most processed magnetic
    column, ``cell`` a quarter of the line spacing rounded down to 1, 2, 2.5
    or 5 × 10ᵏ m, ``blanking`` one line spacing; ``extent`` =
    ``(xmin, xmax, ymin, ymax)`` in m with ``cell``. ``max_sweeps`` (1 to
    100000) and ``convergence`` (the largest change of a sweep, default
    10⁻⁴ × the data's RMS about their plane) are minimum curvature's limits,
    GMT ``surface``'s ``-N`` and ``-C``. ``xy`` = ``(easting, northing)``
    names columns of positions already projected (m), gridded as they are
    (found in a flight without lat/lon: ``x``/``y``, ``easting``/``northing``,
    ``utm_x``/``utm_y``, ``utm-x``/``utm-y``, any case); ``utm_zone`` is then their zone, the
    grid's CRS, without which the grid has none (warning ``[no-crs]``).

    Returns a :class:`Grid`: ``values`` (ny × nx, row 0 south, NaN blank),
    ``x``, ``y`` (m), ``epsg``, ``info`` (line spacing, blanking,
    convergence), ``vertical_derivative()``, ``upward(h)``, ``minus(g)``,
    ``sample(x, y)``, ``write(path)`` (``.tif``, ``.asc``, ``.nc``, ``.gxf``).
    """
    from .tolles_lawson import progress_callback

    return _aeromag.grid_flight(
        flight,
        column=column,
        cell=cell,
        tension=tension,
        method=method,
        blanking=blanking,
        utm_zone=utm_zone,
        lever_arm=lever_arm,
        extent=extent,
        max_sweeps=max_sweeps,
        convergence=convergence,
        xy=xy,
        progress=progress_callback(progress),
    )


def read_grid(path: PathLike) -> Grid:
    """Read a grid file: GeoTIFF, ESRI ASCII, netCDF (classic or netCDF-4), GXF (as ``aeromag
    grid`` writes them), a Surfer ``.grd`` or an Oasis montaj (Geosoft) ``.grd``."""
    return _aeromag.read_grid(os.fspath(path))


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
    progress: Any = None,
) -> Microlevelled:
    """Micro-level a levelled survey (``aeromag microlevel``, Minty 1991).

    ``cutoff`` (at least 2) is the high-pass's cut-off wavelength in line
    spacings; ``tension``, ``max_sweeps`` and ``convergence`` are those of
    the working grid's minimum curvature, as in :func:`grid_flight`, and so
    are ``utm_zone`` and ``xy``.

    Returns a :class:`Microlevelled`: ``values``, ``correction`` (nT per
    row), ``correction_nt`` (RMS, largest), ``gridding`` (the working
    grid's sweeps and whether it converged), ``to_flight()`` with
    ``<column>_mlev`` and ``<column>_mlev_corr``.
    """
    from .tolles_lawson import progress_callback

    return _aeromag.microlevel(
        flight,
        column=column,
        cell=cell,
        cutoff=cutoff,
        along_line=along_line,
        cosine_power=cosine_power,
        tension=tension,
        utm_zone=utm_zone,
        lever_arm=lever_arm,
        max_sweeps=max_sweeps,
        convergence=convergence,
        xy=xy,
        progress=progress_callback(progress),
    )


from .batch import batch  # noqa: E402


def dipole_crlb(config: Union[None, PathLike] = None) -> Dict[str, Any]:
    """The Cramér–Rao bound of a gradiometer pass (``aeromag dipole crlb --json``):
    standard deviations of position (m) and moment (A·m²) from every epoch up
    to the closest approach and to the end of the pass; ``config`` a
    gradiometer scenario file (default: the built-in pass)."""
    import json

    return json.loads(_aeromag.dipole_crlb(None if config is None else os.fspath(config)))
