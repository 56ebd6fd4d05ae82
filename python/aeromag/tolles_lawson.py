"""Tolles-Lawson compensation as a scikit-learn-style estimator.

:class:`TollesLawson` follows scikit-learn's estimator conventions without
depending on scikit-learn: the keyword options are stored as given,
``fit(flight)`` returns the estimator, fitted attributes end in ``_``,
``get_params``/``set_params`` work as there. The options are the CLI's
``aeromag calibrate`` flags with ``-`` → ``_`` (``--lambda`` is
``ridge_lambda``), and are turned into the library's settings by the same
code as the flags, so that Python and CLI fit the same model.
"""

from __future__ import annotations

import inspect
import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _aeromag
from ._aeromag import Flight, SensorsModel, TlModel

FlightLike = Union[Flight, Dict[str, Any], Any]


def as_flight(x: FlightLike) -> Flight:
    """A :class:`Flight` from a Flight, a dict of arrays or a DataFrame."""
    if isinstance(x, Flight):
        return x
    if isinstance(x, dict):
        return Flight.from_dict(x)
    if hasattr(x, "columns") and hasattr(x, "to_numpy"):
        return Flight.from_pandas(x)
    raise TypeError(f"flight must be an aeromag.Flight, a dict of arrays or a DataFrame, got {type(x).__name__}")


def progress_callback(progress: Any) -> Optional[Callable[[str, int, int], None]]:
    """A ``progress(stage, done, total)`` callable from ``progress=``: None,
    such a callable, ``True`` (a tqdm bar, if tqdm is installed), or a
    tqdm-like bar (anything with ``update`` and ``total``)."""
    if progress is None or progress is False:
        return None
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return None
        progress = tqdm(leave=False)
    if hasattr(progress, "update") and hasattr(progress, "total"):
        bar = progress
        state = {"done": 0, "stage": None}

        def update(stage: str, done: int, total: int) -> None:
            if stage != state["stage"]:
                state["stage"] = stage
                state["done"] = 0
                if hasattr(bar, "reset"):
                    bar.reset(total=total or None)
                if stage and hasattr(bar, "set_description"):
                    bar.set_description(stage)
            if total and bar.total != total:
                bar.total = total
            if done > state["done"]:
                bar.update(done - state["done"])
                state["done"] = done

        return update
    if callable(progress):
        return progress
    raise TypeError("progress must be None, True, a callable(stage, done, total) or a tqdm bar")


class TollesLawson:
    """Tolles-Lawson / Leliak aircraft interference model (``aeromag calibrate``).

    ``method="ls"``: band-pass least squares (Butterworth order 4,
    zero-phase, ``band`` Hz, ``trim`` samples dropped at each end of each
    leg), the industry and MagNav.jl baseline. ``method="kalman"``: the
    Kalman filter and smoother with a stochastic model of the external
    field along the track (the thesis' method; needs ``alt`` and ground
    speed).

    Options (the CLI's flags; ``None`` = the library's default):

    - ``terms``: term groups, e.g. ``"p3,i5,e8"`` (16 terms), ``"p3,i6,e9"``;
    - ``extra``: extra regressors, recorded channels times the direction
      cosines, e.g. ``["cur_strb", "cur_flap:lag"]`` (``:lag``: also through
      a first-order lag fitted on the flight); the CLI's ``--extra``;
    - ``extra_selection``: ``"test"`` (keep the ``extra`` channels the
      likelihood-ratio test finds to matter, drop the others with a note)
      or ``"all"``; the CLI's ``--extra-selection``;
    - ``magnitude``: ``"first-order"`` (the Tolles-Lawson projection) or
      ``"exact"`` (``|B + ΔB| − |B|`` by Gauss–Newton, method ``ls``);
    - ``convention``: ``"physical"`` (eddy terms in nT/s) or ``"magnav"``
      (MagNav.jl's per-sample difference);
    - ``ridge_lambda``: ridge parameter λ ≥ 0 (``--lambda``);
    - ``band``: pass band ``(lo, hi)`` in Hz, or None to fit unfiltered data;
    - ``trim``: samples trimmed per leg end; ``bt_scale``: scale of the
      induced and eddy columns, nT; ``no_split_lines``: one leg;
    - ``reference``: known external-field channels removed first:
      ``"auto"`` (``diurnal`` and ``igrf`` when present), ``"none"``, or a
      list of columns;
    - ``eddy_lag``: ``"auto"``, ``"none"`` or lags in s (``[0.3, 0.8]``);
      None: ``auto``, or ``none`` with ``convention="magnav"``;
    - ``lever_arm``: sensor position ``(x, y, z)`` m from the navigation
      point (body frame); ``date``: ``"YYYY-MM-DD"`` or decimal year of the
      flight, for the main-field gradient used with the lever arm;
    - Kalman: ``tune`` (None: tune unless ``kalman_noise`` is given),
      ``no_tune``, ``kalman_noise=(q1, q2, r)``, ``field_order`` (2–6),
      ``series`` (keep the per-row series in ``series_``).

    Fitted attributes: ``model_`` (:class:`TlModel`), ``coef_``,
    ``coef_std_`` (nT per term unit), ``terms_`` (names), ``notes_``
    (notes and warnings), ``fit_stats_``, ``series_`` (Kalman, with
    ``series=True``).
    """

    def __init__(
        self,
        method: str = "ls",
        *,
        terms: str = "p3,i5,e8",
        extra: Union[None, str, Sequence[str]] = None,
        extra_selection: str = "test",
        magnitude: str = "first-order",
        convention: str = "physical",
        ridge_lambda: float = 0.0,
        band: Optional[Tuple[float, float]] = (0.1, 0.9),
        trim: int = 20,
        bt_scale: float = 50000.0,
        no_split_lines: bool = False,
        reference: Union[str, Sequence[str]] = "auto",
        eddy_lag: Union[None, str, Sequence[float]] = None,
        lever_arm: Optional[Tuple[float, float, float]] = None,
        date: Union[str, float] = "2025-01-01",
        tune: Optional[bool] = None,
        no_tune: bool = False,
        kalman_noise: Optional[Tuple[float, float, float]] = None,
        field_order: Optional[int] = None,
        series: bool = False,
    ) -> None:
        self.method = method
        self.terms = terms
        self.extra = extra
        self.extra_selection = extra_selection
        self.magnitude = magnitude
        self.convention = convention
        self.ridge_lambda = ridge_lambda
        self.band = band
        self.trim = trim
        self.bt_scale = bt_scale
        self.no_split_lines = no_split_lines
        self.reference = reference
        self.eddy_lag = eddy_lag
        self.lever_arm = lever_arm
        self.date = date
        self.tune = tune
        self.no_tune = no_tune
        self.kalman_noise = kalman_noise
        self.field_order = field_order
        self.series = series

    # -- scikit-learn conventions -------------------------------------------------

    @classmethod
    def _param_names(cls) -> List[str]:
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    @classmethod
    def _defaults(cls) -> Dict[str, Any]:
        return {k: p.default for k, p in inspect.signature(cls.__init__).parameters.items() if k != "self"}

    def get_params(self, deep: bool = True) -> Dict[str, Any]:
        """The keyword options, as given."""
        return {k: getattr(self, k) for k in self._param_names()}

    def _settings(self) -> Dict[str, Any]:
        """The options the library is given: with ``method="kalman"`` the
        band-pass LS settings are left out at their defaults (changed, the
        library refuses them: the Kalman method does not filter)."""
        params = self.get_params()
        if params.get("method") == "kalman":
            defaults = self._defaults()
            for k in ("ridge_lambda", "band", "trim"):
                if params[k] == defaults[k]:
                    del params[k]
        return params

    def set_params(self, **params: Any) -> "TollesLawson":
        """Set keyword options; returns the estimator."""
        names = self._param_names()
        for k, v in params.items():
            if k not in names:
                raise ValueError(f"invalid parameter '{k}' for TollesLawson (parameters: {', '.join(names)})")
            setattr(self, k, v)
        return self

    def __repr__(self) -> str:
        defaults = self._defaults()
        changed = [f"{k}={v!r}" for k, v in self.get_params().items() if v != defaults[k]]
        return f"TollesLawson({', '.join(changed)})"

    # -- fitting and applying -----------------------------------------------------

    def fit(self, flight: FlightLike, y: Any = None, progress: Any = None) -> "TollesLawson":
        """Fit the model on a calibration flight; returns the estimator.

        ``flight``: a :class:`Flight`, a dict of arrays or a DataFrame
        (columns named as in the files); ``y`` is ignored (scikit-learn's
        signature); ``progress``: a callable ``(stage, done, total)``, a
        tqdm bar, or True. The GIL is released while fitting.
        """
        model = _aeromag.calibrate(as_flight(flight), self._settings(), progress_callback(progress))
        self._set_fitted(model)
        return self

    def _set_fitted(self, model: TlModel) -> None:
        self.model_ = model
        self.coef_ = model.coef
        self.coef_std_ = model.coef_std
        self.terms_ = model.terms
        self.notes_ = model.notes
        self.fit_stats_ = model.fit_stats
        self.series_ = model.series

    def _fitted(self) -> TlModel:
        model = getattr(self, "model_", None)
        if model is None:
            raise AttributeError("this TollesLawson is not fitted yet: call fit(flight) first")
        return model

    def predict(self, flight: FlightLike) -> np.ndarray:
        """The modelled interference of every row, nT (NaN where an input is missing)."""
        return self._fitted().interference(as_flight(flight))

    def transform(self, flight: FlightLike) -> np.ndarray:
        """The compensated reading ``mag − interference`` of every row, nT."""
        return self._fitted().compensate(as_flight(flight))

    def fit_transform(self, flight: FlightLike, y: Any = None, progress: Any = None) -> np.ndarray:
        """``fit(flight)`` then ``transform(flight)``."""
        return self.fit(flight, progress=progress).transform(flight)

    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Write the model file, byte for byte what ``aeromag calibrate`` writes."""
        self._fitted().save(os.fspath(path))

    @classmethod
    def from_model(cls, model: TlModel) -> "TollesLawson":
        """A fitted estimator around a model (e.g. from :func:`load_model`)."""
        est = cls(method=model.method)
        est._set_fitted(model)
        return est


def calibrate_sensors(
    flight: FlightLike,
    mag: Union[str, Sequence[str]],
    vector: Union[None, str, Sequence[str]] = None,
    reference_sensor: Optional[str] = None,
    progress: Any = None,
    **options: Any,
) -> SensorsModel:
    """One Tolles-Lawson model per scalar sensor (``aeromag calibrate --mag
    A,B,…``), returned as the multi-sensor model file (:class:`SensorsModel`).

    ``mag``: the scalar sensors' columns (``["mag_1_uc", "mag_4_uc"]`` or
    ``"mag_1_uc,mag_4_uc"``); ``vector``: the vector magnetometer by prefix,
    one for all (``"flux_a"``) or one per sensor (default: the flight's
    ``flux_x/y/z``); ``reference_sensor``: the reference-sensor mode, a
    sensor of ``mag`` (fitted first; its compensated reading is the others'
    external-field reference on every row) or an already compensated column
    such as ``"mag_1_c"``; ``options``: the keyword options of
    :class:`TollesLawson` (``extra=[...]``, ``extra_selection``,
    ``magnitude="exact"``, ``method="kalman"`` …).

    The model applies itself: ``model.compensate(flight)`` gives the
    ``<name>_interf``, ``<name>_comp`` and ``<name>_grad`` arrays,
    ``model.apply(flight)`` the flight with them, ``model.score(flight)``
    the figures of ``aeromag report`` for it.
    """
    params = TollesLawson(**options)._settings()
    names = [m.strip() for m in mag.split(",")] if isinstance(mag, str) else list(mag)
    vectors = [v.strip() for v in vector.split(",")] if isinstance(vector, str) else vector
    return _aeromag.calibrate_sensors(
        as_flight(flight),
        names,
        params,
        vector=None if vectors is None else list(vectors),
        reference_sensor=reference_sensor,
        progress=progress_callback(progress),
    )


def load_model(path: Union[str, "os.PathLike[str]"]) -> Any:
    """Read a model file written by the CLI or ``save``: a :class:`TlModel`
    (``aeromag calibrate``), a :class:`SensorsModel` (``aeromag calibrate
    --mag A,B,…``), or a :class:`Model` (``aeromag rotor fit``, ``aeromag
    pod fit``), by the file's ``kind``.

    A model applies itself: ``model.interference(flight)``,
    ``model.compensate(flight)``, ``model.apply(flight)`` (the flight with
    the output columns); ``TollesLawson.from_model(model)`` gives the
    estimator interface of a Tolles-Lawson model.
    """
    return _aeromag.load_model(os.fspath(path))
