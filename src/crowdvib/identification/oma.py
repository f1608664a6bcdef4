"""Operational modal analysis of the empty bridge (docs: theory, Operational modal analysis).

The estimator assumes the empty bridge's modal model known; the most accurate source is system
identification on ambient vibration data [VNVdB23]. :func:`identify_modes` runs covariance-driven
stochastic subspace identification (SSI-cov) through pyOMA2 (the ``oma`` extra) over a range of
model orders, keeps the poles that pyOMA2's stability criteria call stable, groups them by
frequency and reports per physical mode the median frequency and damping ratio over its stable
poles, with a standard deviation that is the larger of (a) the first-order (perturbation)
standard deviation pyOMA2 propagates from the scatter of the output covariances over data blocks
and (b) the scatter of the stable poles over the model orders.

OMA gives no modal masses: :meth:`ModeIdentification.modal_model` takes them from an FE model (or
a mass the user states).
"""

from __future__ import annotations

import contextlib
import io
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._validation import as_float_array, check_positive
from ..errors import DataError, EstimationError, ParameterError
from ..models.structure import ModalModel

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

__all__ = ["ModeIdentification", "ambient_response", "identified_error_levels", "identify_modes"]

#: Stable poles closer than this relative frequency gap belong to one mode.
CLUSTER_TOLERANCE = 0.01
#: A mode must be stable at this share of the model orders that have any stable pole.
MIN_STABLE_SHARE = 0.3


def _pyoma2():
    try:
        from pyoma2.algorithms import SSI
        from pyoma2.setup import SingleSetup
    except ImportError:
        raise ImportError("operational modal analysis needs pyOMA2: "
                          "pip install 'crowdvib[oma]'") from None
    return SSI, SingleSetup


@dataclass(frozen=True)
class ModeIdentification:
    """Modes identified from an ambient record (docs: theory, Operational modal analysis).

    Attributes
    ----------
    frequencies, damping_ratios : ndarray, (n_modes,)
        f_j [Hz] and ξ_j [-]: medians over the mode's stable poles.
    frequency_std, damping_std : ndarray, (n_modes,)
        Standard deviations [Hz], [-] (larger of the propagated and the over-orders scatter).
    mode_shapes : ndarray, (n_sensors, n_modes)
        Real mode shapes at the sensors, +1 at the largest component.
    sensor_names : tuple of str
    sample_rate : float
    poles : dict
        The stabilisation diagram: ``frequency``, ``damping`` and ``stable`` arrays of shape
        (n_poles, n_orders), and ``orders``.
    method : str
    """

    frequencies: np.ndarray
    damping_ratios: np.ndarray
    frequency_std: np.ndarray
    damping_std: np.ndarray
    mode_shapes: np.ndarray
    sensor_names: tuple
    sample_rate: float
    poles: dict
    method: str = "ssi-cov"

    @property
    def n_modes(self) -> int:
        return self.frequencies.size

    def modal_model(self, structure: ModalModel | None = None, *,
                    modal_masses: ArrayLike | None = None,
                    sensor_positions: ArrayLike | None = None,
                    walkway: tuple[float, float] | None = None, width: float | None = None,
                    name: str = "identified footbridge") -> ModalModel:
        """A :class:`ModalModel` with the identified frequencies and damping ratios.

        The estimator needs the mode shapes along the whole walkway and the modal masses, which
        an ambient test with a few sensors does not give. Two ways:

        * ``structure`` — an FE :class:`ModalModel` whose outputs are the sensors (same names):
          each identified mode is paired with the FE mode of highest MAC at the sensors and
          takes the identified f_j and ξ_j; shapes and modal masses stay the FE model's.
        * ``modal_masses`` [kg] (stated by the user, for unity-at-antinode shapes) with
          ``sensor_positions`` [m] along the ``walkway`` = (start, end) [m] and ``width`` [m]:
          shapes linear between the sensors and zero at the walkway's ends (supports there),
          scaled to 1 at their largest value. A coarse shape: prefer an FE model.
        """
        if structure is not None:
            return self._paired_with(structure)
        if modal_masses is None or sensor_positions is None or walkway is None or width is None:
            raise ParameterError("modal_model needs structure (an FE ModalModel at the sensors) "
                                 "or modal_masses, sensor_positions, walkway and width: OMA "
                                 "gives no modal masses")
        masses = check_positive("modal_masses", np.broadcast_to(
            np.asarray(modal_masses, dtype=float), (self.n_modes,)), unit="kg")
        x = as_float_array("sensor_positions", sensor_positions, ndim=1)
        start, end = (float(v) for v in walkway)
        if x.size != self.mode_shapes.shape[0] or np.any(np.diff(x) <= 0) or x[0] <= start \
                or x[-1] >= end:
            raise ParameterError(f"sensor_positions must give one increasing position per sensor "
                                 f"({self.mode_shapes.shape[0]}) strictly inside the walkway "
                                 f"[{start:g}, {end:g}] m, got {x.tolist()}")
        stations = np.concatenate([[start], x, [end]])
        shapes = np.vstack([np.zeros(self.n_modes), self.mode_shapes, np.zeros(self.n_modes)])
        peak = shapes[np.argmax(np.abs(shapes), axis=0), np.arange(self.n_modes)]
        shapes = shapes / peak
        return ModalModel(frequencies=self.frequencies, damping_ratios=self.damping_ratios,
                          modal_masses=masses, positions=stations - start, mode_shapes=shapes,
                          width=width, output_names=self.sensor_names,
                          output_shapes=shapes[1:-1], name=name)

    def _paired_with(self, structure):
        missing = [n for n in self.sensor_names if n not in structure.output_names]
        if missing:
            raise ParameterError(f"structure must have the sensors {list(self.sensor_names)} as "
                                 f"outputs, missing {missing}")
        rows = structure.output_shapes[structure.output_index(self.sensor_names)]
        mac = _mac(self.mode_shapes, rows)                   # (identified, FE)
        pairs = np.argmax(mac, axis=1)
        if np.unique(pairs).size != pairs.size:
            raise EstimationError(f"two identified modes pair with the same FE mode (MAC "
                                  f"{np.round(mac, 2).tolist()})")
        frequencies = structure.frequencies.copy()
        damping = structure.damping_ratios.copy()
        frequencies[pairs] = self.frequencies
        damping[pairs] = self.damping_ratios
        return structure.replace(frequencies=frequencies, damping_ratios=damping)

    def error_levels(self, levels: Mapping[str, Sequence[float]] | None = None
                     ) -> dict[str, tuple[float, ...]]:
        """Modelling-error levels for :func:`~crowdvib.identification.modelling_error_study`
        from this identification (see :func:`identified_error_levels`)."""
        return identified_error_levels(self.frequencies, self.frequency_std, self.damping_ratios,
                                       self.damping_std, levels)

    def plot_stabilisation(self, ax: "Axes | None" = None) -> "Figure | SubFigure":
        """Stabilisation diagram: poles per model order, stable ones filled, modes marked."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7, 4))
        order = np.broadcast_to(self.poles["orders"], self.poles["frequency"].shape)
        stable = self.poles["stable"]
        ax.plot(self.poles["frequency"][~stable], order[~stable], "x", color="0.7", ms=3,
                label="pole")
        ax.plot(self.poles["frequency"][stable], order[stable], "o", color="C0", ms=3,
                label="stable pole")
        for f in self.frequencies:
            ax.axvline(f, color="C3", lw=0.8)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("model order")
        ax.set_title("SSI-cov stabilisation diagram")
        ax.legend(loc="lower right")
        return ax.figure


def identified_error_levels(frequencies: ArrayLike, frequency_std: ArrayLike,
                            damping_ratios: ArrayLike, damping_std: ArrayLike,
                            levels: Mapping[str, Sequence[float]] | None = None
                            ) -> dict[str, tuple[float, ...]]:
    """Modelling-error levels whose ε_f and ε_ξ come from an identification, not fixed percentages.

    One and two relative standard deviations (σ_f/f, σ_ξ/ξ) of the least certain identified mode
    (docs: theory, Operational modal analysis); the other parameters keep ``levels`` (default the
    paper's ``PAPER_ERROR_LEVELS``).
    """
    from .studies import PAPER_ERROR_LEVELS

    result = dict(PAPER_ERROR_LEVELS if levels is None else levels)
    for name, value, std in (("frequencies", frequencies, frequency_std),
                             ("damping_ratios", damping_ratios, damping_std)):
        value = check_positive(name, np.asarray(value, dtype=float))
        std = np.asarray(std, dtype=float)
        if std.shape != value.shape or not np.all(np.isfinite(std) & (std >= 0)):
            raise ParameterError(f"{name} standard deviations must be finite, >= 0 and one per "
                                 f"mode ({value.size}), got {std.tolist()}")
        worst = float(np.max(std / value))
        if worst == 0:
            raise ParameterError(f"{name} standard deviations are all 0: no error level from them")
        result[name] = (worst, 2 * worst)
    return result


def _mac(a, b):
    """Modal assurance criterion between the columns of a and of b."""
    num = np.abs(a.T @ b) ** 2
    return num / np.outer((a * a).sum(axis=0), (b * b).sum(axis=0))


def identify_modes(signals: ArrayLike, sample_rate: float, *, n_modes: int | None = None,
                   frequency_band: tuple[float, float] | None = None, method: str = "ssi-cov",
                   block_rows: int | None = None, max_order: int = 40, n_blocks: int = 50,
                   sensor_names: Sequence[str] | None = None) -> ModeIdentification:
    """Modes of the empty bridge from an ambient record by SSI-cov (docs: theory, Operational modal analysis).

    Parameters
    ----------
    signals : array_like, shape (n_sensors, n_samples)
        Ambient accelerations [m/s²] (any consistent unit).
    sample_rate : float
        [Hz].
    n_modes : int, optional
        Number of modes to report (the most consistently stable ones); default every mode stable
        at ≥ 30 % of the model orders.
    frequency_band : (float, float), optional
        Modes outside are ignored [Hz]; default (0, Nyquist).
    method : {"ssi-cov"}
        Covariance-driven SSI through pyOMA2.
    block_rows : int, optional
        Block rows of the Hankel matrix; default enough for two periods of the lowest band
        frequency (at least 20).
    max_order : int
        Highest model order of the stabilisation diagram.
    n_blocks : int
        Data blocks for the propagated uncertainty.
    sensor_names : sequence of str, optional

    Returns
    -------
    ModeIdentification
    """
    if method != "ssi-cov":
        raise ParameterError(f"method must be 'ssi-cov', got {method!r}")
    data = as_float_array("signals", signals)
    if data.ndim != 2 or data.shape[0] < 1 or data.shape[1] < 100:
        raise ParameterError(f"signals must have shape (n_sensors, n_samples) with at least 100 "
                             f"samples, got {np.shape(signals)}")
    if not np.all(np.isfinite(data)):
        raise DataError("signals must be finite")
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    low, high = (0.0, sample_rate / 2) if frequency_band is None else (
        float(frequency_band[0]), float(frequency_band[1]))
    if not 0 <= low < high <= sample_rate / 2:
        raise ParameterError(f"frequency_band must satisfy 0 <= low < high <= Nyquist "
                             f"({sample_rate / 2:g} Hz), got {frequency_band!r}")
    names = (tuple(f"sensor_{i + 1}" for i in range(data.shape[0])) if sensor_names is None
             else tuple(str(n) for n in sensor_names))
    if len(names) != data.shape[0]:
        raise ParameterError(f"sensor_names must name {data.shape[0]} sensors, got {len(names)}")
    if block_rows is None:
        block_rows = max(20, int(np.ceil(2 * sample_rate / max(low, sample_rate / 100))))
    SSI, SingleSetup = _pyoma2()
    algorithm = SSI(name="ssi", method="cov", br=int(block_rows), ordmax=int(max_order),
                    calc_unc=True, nb=int(n_blocks))
    setup = SingleSetup(data.T, fs=sample_rate)
    setup.add_algorithms(algorithm)
    logger = logging.getLogger("pyoma2")
    level = logger.level
    logger.setLevel(logging.WARNING)
    try:
        with contextlib.redirect_stderr(io.StringIO()):         # pyOMA2's progress bars
            setup.run_by_name("ssi")
    finally:
        logger.setLevel(level)
    result = algorithm.result
    return _from_poles(result, names, sample_rate, low, high, n_modes)


def _from_poles(result, names, sample_rate, low, high, n_modes):
    """Group the stable poles into modes (docs: theory, Operational modal analysis)."""
    frequency = np.asarray(result.Fn_poles, dtype=float)
    damping = np.asarray(result.Xi_poles, dtype=float)
    shapes = np.asarray(result.Phi_poles)
    f_std = np.asarray(result.Fn_poles_std, dtype=float)
    xi_std = np.asarray(result.Xi_poles_std, dtype=float)
    stable = ((np.asarray(result.Lab) == 1) & np.isfinite(frequency) & (frequency >= low)
              & (frequency <= high) & np.isfinite(damping) & (damping > 0))
    orders = np.arange(frequency.shape[1])
    pole, column = np.nonzero(stable)
    if pole.size == 0:
        raise EstimationError("no stable pole in the frequency band: the record is too short or "
                              "too noisy for SSI, or the band misses the modes")
    sort = np.argsort(frequency[pole, column])
    pole, column = pole[sort], column[sort]
    values = frequency[pole, column]
    breaks = np.flatnonzero(np.diff(values) > CLUSTER_TOLERANCE * values[:-1]) + 1
    clusters = np.split(np.arange(values.size), breaks)
    orders_with_poles = np.unique(column).size
    support = np.array([np.unique(column[c]).size for c in clusters])
    ranked = np.argsort(-support, kind="stable")
    if n_modes is None:
        chosen = ranked[support[ranked] >= MIN_STABLE_SHARE * orders_with_poles]
    else:
        if int(n_modes) != n_modes or n_modes < 1:
            raise ParameterError(f"n_modes must be a positive integer, got {n_modes!r}")
        if ranked.size < n_modes:
            raise EstimationError(f"only {ranked.size} stable mode(s) in the band, n_modes = "
                                  f"{n_modes} asked")
        chosen = ranked[:int(n_modes)]
    rows = []
    for c in clusters_sorted(chosen, clusters, values):
        p, o = pole[c], column[c]
        f, xi = frequency[p, o], damping[p, o]
        nearest = np.argmin(np.abs(f - np.median(f)))
        phi = np.real(shapes[p[nearest], o[nearest]])
        phi = phi / phi[np.argmax(np.abs(phi))]
        # The propagated std of single poles is erratic at some orders: its median over the
        # mode's stable poles, or the scatter over the orders if that is larger.
        rows.append((np.median(f), np.median(xi),
                     max(_median_finite(f_std[p, o]), f.std(ddof=1) if f.size > 1 else 0.0),
                     max(_median_finite(xi_std[p, o]), xi.std(ddof=1) if xi.size > 1 else 0.0),
                     phi))
    return ModeIdentification(
        frequencies=np.array([r[0] for r in rows]), damping_ratios=np.array([r[1] for r in rows]),
        frequency_std=np.array([r[2] for r in rows]), damping_std=np.array([r[3] for r in rows]),
        mode_shapes=np.column_stack([r[4] for r in rows]), sensor_names=names,
        sample_rate=sample_rate,
        poles={"frequency": np.where(np.isfinite(frequency), frequency, np.nan),
               "damping": damping, "stable": stable, "orders": orders})


def _median_finite(values):
    values = values[np.isfinite(values)]
    return float(np.median(values)) if values.size else 0.0


def clusters_sorted(chosen, clusters, values):
    """The chosen clusters in order of increasing frequency."""
    return [clusters[i] for i in sorted(chosen, key=lambda i: np.median(values[clusters[i]]))]


def ambient_response(structure: ModalModel, duration: float, sample_rate: float,
                     load_psd: ArrayLike,
                     rng: int | np.random.Generator | None = None) -> np.ndarray:
    """Ambient accelerations [m/s²] of the empty bridge at its outputs, shape (n_outputs, N).

    Independent white-noise modal loads with one-sided PSD ``load_psd`` [N²/Hz] (one value, or
    one per mode): each modal acceleration is an exact Gaussian record of the PSD
    |ω² H_j(ω)|² S_q / m_j², H_j = 1/(ω_j² − ω² + 2iξ_jω_jω) [CP03] (docs: theory, Operational
    modal analysis), summed through the output shapes. For testing identification.
    """
    from ..signals.synthesis import gaussian_record, record_frequencies

    omega = 2 * np.pi * record_frequencies(duration, sample_rate)
    natural = 2 * np.pi * structure.frequencies[:, np.newaxis]
    masses = structure.modal_masses[:, np.newaxis]
    damping = structure.damping_ratios[:, np.newaxis]
    load = check_positive("load_psd", np.broadcast_to(np.asarray(load_psd, dtype=float),
                                                      (structure.n_modes,)), unit="N²/Hz")
    frf = omega**2 / (masses * (natural**2 - omega**2 + 2j * damping * natural * omega))
    modal = gaussian_record(np.abs(frf) ** 2 * load[:, np.newaxis], sample_rate, rng=rng)
    return structure.output_shapes @ modal
