"""Operational modal analysis of the empty bridge (docs: theory, Operational modal analysis).

The estimator assumes the empty bridge's modal model known; the most accurate source is system
identification on ambient vibration data [VNVdB23]. :func:`identify_modes` runs one of two
methods on an ambient record:

* ``"ssi-cov"``: covariance-driven stochastic subspace identification through pyOMA2 (the
  ``oma`` extra) over a range of model orders; the poles pyOMA2's stability criteria call stable
  are grouped by frequency and each physical mode gets the median frequency and damping ratio
  over its stable poles, with a standard deviation that is the larger of (a) the first-order
  (perturbation) standard deviation pyOMA2 propagates from the scatter of the output
  covariances over data blocks and (b) the scatter of the stable poles over the model orders;
* ``"efdd"``: enhanced frequency domain decomposition (:mod:`crowdvib.oma.efdd`).

``cross_check=True`` runs the other method too and compares them mode by mode
(:class:`~crowdvib.oma.modeid.ModeCrossCheck`); ``reference_sensors`` merges several
setups (:mod:`crowdvib.oma.multisetup`). OMA gives no modal masses:
:meth:`ModeIdentification.modal_model` takes them from an FE model (or a mass the user states).
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import warnings
from collections.abc import Callable, Sequence
from unittest import mock

import numpy as np
from numpy.typing import ArrayLike

from .._validation import check_positive
from ..errors import DataError, EstimationError, IdentifiabilityWarning, ParameterError
from ..models.structure import ModalModel
from .efdd import MAC_THRESHOLD, efdd_modes
from .modeid import (PAIRING_TOLERANCE, ModeIdentification, compare_identifications,
                     identified_error_levels, information_bound)
from .multisetup import _names, _signals, identify_setups
from ..signals.synthesis import gaussian_record, record_frequencies

__all__ = ["ModeIdentification", "ambient_response", "identified_error_levels", "identify_modes",
           "METHODS"]

#: Identification methods; each is the other's cross-check.
METHODS = ("ssi-cov", "efdd")
#: Stable poles closer than this relative frequency gap belong to one mode.
CLUSTER_TOLERANCE = 0.01
#: A mode must be stable at this share of the model orders that have any stable pole.
MIN_STABLE_SHARE = 0.3
#: ... its stable poles must share one shape (median MAC with the mode's at least this), and it
#: must be resolved: σ_ξ < ξ or σ_f < ξ f (the half-power half-width). At the information
#: bound both ratios are (2π f ξ T)^-1/2, so 1 means less data than one decay time.
MIN_SHAPE_MAC = 0.9
#: SSI-cov's default block rows: their lags span this many periods of the lowest frequency of
#: interest (the Hankel matrix's correlations twice that). More lags cost CPU as block rows⁴ in
#: pyOMA2's uncertainty propagation; fewer widen the lightly damped modes' scatter (issue 27).
LAG_PERIODS = 2
#: The lowest frequency of interest when the band starts at 0 [Hz]. Its lags still span one
#: period at 0.5 Hz (the lowest lateral pacing frequencies), twice the usual minimum of half a
#: period; give the band for lower modes.
LOWEST_FREQUENCY = 1.0
#: SSI-cov's default model order with ``n_modes``: two poles per mode, twice over for the noise
#: poles, plus this margin; without ``n_modes`` ``DEFAULT_ORDER`` (room for about ten modes).
ORDER_MARGIN = 8
DEFAULT_ORDER = 40
#: SSI-cov runs on the record decimated to a Nyquist frequency at least this many times the band's
#: upper end (fewer samples and block rows for the same lags; the anti-alias FIR is flat there).
NYQUIST_MARGIN = 1.25


def _pyoma2():
    try:
        from pyoma2.algorithms import SSI
        from pyoma2.setup import SingleSetup
    except ImportError:
        raise ImportError("operational modal analysis needs pyOMA2: "
                          "pip install 'crowdvib[oma]'") from None
    return SSI, SingleSetup


def identify_modes(signals: ArrayLike | Sequence[ArrayLike], sample_rate: float, *,
                   n_modes: int | None = None,
                   frequency_band: tuple[float, float] | None = None, method: str = "ssi-cov",
                   cross_check: bool = False,
                   reference_sensors: Sequence[Sequence[int]] | None = None,
                   block_rows: int | None = None, max_order: int | None = None,
                   n_blocks: int = 50, segment_length: int | None = None,
                   mac_threshold: float = MAC_THRESHOLD,
                   sensor_names: Sequence[str] | Sequence[Sequence[str]] | None = None,
                   progress: Callable[[int, int], None] | None = None) -> ModeIdentification:
    """Modes of the empty bridge from an ambient record (docs: theory, Operational modal analysis).

    Parameters
    ----------
    signals : array_like, shape (n_sensors, n_samples), or a sequence of them
        Ambient accelerations [m/s²] (any consistent unit). Several setups (each its own array,
        of any length) with ``reference_sensors``.
    sample_rate : float
        [Hz] (the same for every setup).
    n_modes : int, optional
        Number of modes to report. SSI-cov: the most consistently stable ones, default every
        mode stable at ≥ 30 % of the model orders; EFDD: the most prominent peaks of the first
        singular value, default every peak 0.5 decades above its sides.
    frequency_band : (float, float), optional
        Modes outside are ignored [Hz]; default (0, Nyquist).
    method : {"ssi-cov", "efdd"}
        SSI-cov through pyOMA2, or crowdvib's EFDD.
    cross_check : bool
        Also run the other method and compare the two mode by mode (``cross_check`` of the
        result): SSI-cov is checked by EFDD at its frequencies, EFDD by SSI-cov.
    reference_sensors : sequence of sequences of int, optional
        Several setups: per setup the row indices of the reference sensors (the same sensors,
        in the same order, in every setup). Each setup is identified alone; the shapes are
        merged by rescaling on the references, f and ξ averaged (see ``setups`` of the result).
    block_rows : int, optional
        SSI-cov: block rows of the Hankel matrix; default enough lags for ``LAG_PERIODS``
        periods of the band's lower end (``LOWEST_FREQUENCY`` for a band from 0), at least 20
        and enough for ``max_order``. SSI-cov runs on the record decimated to the band
        (``NYQUIST_MARGIN``), so a band also saves CPU.
    max_order : int, optional
        SSI-cov: highest model order of the stabilisation diagram; default 4 ``n_modes`` +
        ``ORDER_MARGIN``, or ``DEFAULT_ORDER`` without ``n_modes``. The values used are in
        ``settings`` of the result.
    n_blocks : int
        SSI-cov: data blocks for the propagated uncertainty.
    segment_length : int, optional
        EFDD: Welch segment [samples]; default the largest power of two <= n_samples / 16.
    mac_threshold : float
        EFDD: the SDOF bell's lines have a first singular vector of MAC >= this with the peak's.
    sensor_names : sequence of str (one per row), or per setup a sequence, optional
    progress : callable, optional
        Called as ``progress(done, total)`` as the work advances (SSI-cov: per model order of
        each pass of pyOMA2; EFDD: per run).

    Returns
    -------
    ModeIdentification

    See Also
    --------
    crowdvib.read_modal_model : the modes from a table or an FE export instead.
    crowdvib.oma.ambient_response : records to test it on.

    References
    ----------
    B. Peeters and G. De Roeck, "Reference-based stochastic subspace identification for output-only
    modal analysis", *Mechanical Systems and Signal Processing* 13(6):855–878, 1999.
    Covariance-driven SSI.

    D. Pasca, A. Aloisio, M. M. Rosso and D. F. Margoni, *pyOMA2: Python module for conducting
    operational modal analysis*, version 1.4 (PyPI package ``pyoma-2``). The SSI-cov implementation.

    R. Brincker, L. Zhang and P. Andersen, "Modal identification of output-only systems using
    frequency domain decomposition", *Smart Materials and Structures* 10(3):441–445, 2001. FDD.

    R. Brincker, C. E. Ventura and P. Andersen, "Damping estimation by frequency domain
    decomposition", *Proceedings of IMAC XIX*, 2001, 698–703. EFDD.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    Ten minutes of ambient response of a 2 Hz mode with 1 % damping, identified by EFDD (no
    optional dependency):

    >>> from crowdvib import ModalModel, identify_modes
    >>> from crowdvib.oma import ambient_response
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.01, 50e3)
    >>> record = ambient_response(bridge, 600.0, 50.0, load_psd=1e4, rng=1)
    >>> modes = identify_modes(record, 50.0, frequency_band=(1.0, 4.0), n_modes=1, method="efdd")
    >>> round(float(modes.frequencies[0]), 1)
    2.0
    """
    if method not in METHODS:
        raise ParameterError(f"method must be one of {', '.join(map(repr, METHODS))}, "
                             f"got {method!r}")
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    band = _band(frequency_band, sample_rate)
    if n_modes is not None and (int(n_modes) != n_modes or n_modes < 1):
        raise ParameterError(f"n_modes must be a positive integer, got {n_modes!r}")
    options = _options(block_rows, max_order, n_blocks, segment_length, mac_threshold)
    if options["max_order"] is None:
        options["max_order"] = DEFAULT_ORDER if n_modes is None else 4 * n_modes + ORDER_MARGIN
    runs = (1 if reference_sensors is None else max(len(signals), 1)) * (1 + bool(cross_check))
    count = _Progress(progress, runs * _steps(options["max_order"]))
    if reference_sensors is not None:
        def single(data, names):
            return _identify(data, sample_rate, names, band, n_modes, method, cross_check,
                             options, count)

        return count.done(identify_setups(signals, reference_sensors, sensor_names, single))
    data = _signals("signals", signals)
    return count.done(_identify(data, sample_rate,
                                _names(sensor_names, data.shape[0], "sensor_names"),
                                band, n_modes, method, cross_check, options, count))


def _steps(max_order):
    """Progress steps of one run: pyOMA2's three loops over the model orders."""
    return 3 * max_order + 2


class _Progress:
    """``progress(done, total)`` over every run of one identification; a run that takes fewer
    steps than counted (EFDD) jumps to its share."""

    def __init__(self, callback, total):
        self.callback, self.total, self.count = callback, total, 0
        self.report(0)

    def report(self, steps):
        self.count = min(self.count + steps, self.total)
        if self.callback is not None:
            self.callback(self.count, self.total)

    def run_ended(self, started, steps):
        self.report(max(started + steps - self.count, 0))

    def done(self, result):
        self.report(self.total)
        return result


def _band(frequency_band, sample_rate):
    low, high = (0.0, sample_rate / 2) if frequency_band is None else (
        float(frequency_band[0]), float(frequency_band[1]))
    if not 0 <= low < high <= sample_rate / 2:
        raise ParameterError(f"frequency_band must satisfy 0 <= low < high <= Nyquist "
                             f"({sample_rate / 2:g} Hz), got {frequency_band!r}")
    return low, high


def _options(block_rows, max_order, n_blocks, segment_length, mac_threshold):
    for name, value, least in (("block_rows", block_rows, 2), ("max_order", max_order, 2),
                               ("n_blocks", n_blocks, 2), ("segment_length", segment_length, 64)):
        if value is not None and (int(value) != value or value < least):
            raise ParameterError(f"{name} must be an integer >= {least}, got {value!r}")
    if not 0 < float(mac_threshold) < 1:
        raise ParameterError(f"mac_threshold must lie in (0, 1), got {mac_threshold!r}")
    return {"block_rows": block_rows, "n_blocks": int(n_blocks),
            "max_order": None if max_order is None else int(max_order),
            "segment_length": None if segment_length is None else int(segment_length),
            "mac_threshold": float(mac_threshold)}


def _identify(data, sample_rate, names, band, n_modes, method, cross_check, options,
              count):
    """One setup by ``method``, with the other method's cross-check if asked."""
    flat = [name for name, row in zip(names, data) if np.ptp(row) == 0]
    if flat:
        # A constant row has no covariance: SSI's and EFDD's matrices become singular.
        raise DataError(f"signals of sensor(s) {flat} are constant: an ambient record must "
                        f"vary (a dead or disconnected sensor?)")
    primary = _floored(_run(method, data, sample_rate, names, band, n_modes, options, None,
                            count), data.shape[1] / sample_rate)
    if not cross_check:
        return primary
    other_method = METHODS[1 - METHODS.index(method)]
    try:
        other = _floored(_run(other_method, data, sample_rate, names, band, None, options,
                              primary.frequencies, count), data.shape[1] / sample_rate)
    except EstimationError:                          # found nothing: every mode unconfirmed
        other = _empty(other_method, names, sample_rate)
    return dataclasses.replace(primary, cross_check=compare_identifications(primary, other))


def _floored(modes, duration):
    """The standard deviations raised to the information bound where they fall below it."""
    if not modes.n_modes:
        return modes
    bound_f, bound_xi = information_bound(modes.frequencies, modes.damping_ratios, duration)
    return dataclasses.replace(modes, frequency_std=np.maximum(modes.frequency_std, bound_f),
                               damping_std=np.maximum(modes.damping_std, bound_xi))


def _run(method, data, sample_rate, names, band, n_modes, options, seeds, count):
    started = count.count
    if method == "efdd":
        modes = efdd_modes(data, sample_rate, names, *band, n_modes=n_modes, frequencies=seeds,
                           segment_length=options["segment_length"],
                           mac_threshold=options["mac_threshold"],
                           drop_failed=seeds is not None)
    else:
        modes = _ssi(data, sample_rate, names, band, n_modes, options, count,
                     warn=seeds is None)
    count.run_ended(started, _steps(options["max_order"]))
    return modes


def _empty(method, names, sample_rate):
    none = np.zeros(0)
    return ModeIdentification(none, none, none, none, np.zeros((len(names), 0)), names,
                              sample_rate, {}, method)


def _ssi_settings(n_sensors, sample_rate, band, block_rows, max_order):
    """SSI-cov's decimation and block rows for a record and a band unless given (docs: theory,
    Operational modal analysis, the cost of SSI-cov)."""
    low, high = band
    decimation = max(int(sample_rate / (2 * NYQUIST_MARGIN * high)), 1)
    rate = sample_rate / decimation
    if block_rows is None:
        lowest = low if low > 0 else min(LOWEST_FREQUENCY, high / 2)
        # (block rows − 1) × sensors >= order: pyOMA2's shifted observability matrix is square
        block_rows = max(20, int(np.ceil(LAG_PERIODS * rate / lowest)),
                         -(-max_order // n_sensors) + 1)
    return {"block_rows": int(block_rows), "max_order": int(max_order), "decimation": decimation}


def _decimated(data, factor):
    """The record at 1/``factor`` of its rate: zero-phase FIR low-pass (no poles of its own for
    SSI to find), then every ``factor``-th sample."""
    if factor == 1:
        return data
    from scipy.signal import decimate

    return decimate(data, factor, ftype="fir", axis=1, zero_phase=True)


#: pyOMA2's loops draw tqdm bars through its module's ``trange``: replaced, one run at a time.
_PYOMA2_LOOPS = threading.Lock()


def _ssi(data, sample_rate, names, band, n_modes, options, count, warn=True):
    """SSI-cov through pyOMA2, its stable poles grouped into modes."""
    low, high = band
    settings = _ssi_settings(data.shape[0], sample_rate, band, options["block_rows"],
                             options["max_order"])
    SSI, SingleSetup = _pyoma2()
    from pyoma2.functions import ssi as loops
    from threadpoolctl import threadpool_limits

    algorithm = SSI(name="ssi", method="cov", br=settings["block_rows"],
                    ordmax=settings["max_order"], calc_unc=True, nb=options["n_blocks"])
    setup = SingleSetup(_decimated(data, settings["decimation"]).T,
                        fs=sample_rate / settings["decimation"])
    setup.add_algorithms(algorithm)

    def counted(*bounds):
        for step in range(*bounds):
            yield step
            count.report(1)

    logger = logging.getLogger("pyoma2")
    level = logger.level
    logger.setLevel(logging.WARNING)
    try:
        # One BLAS thread: pyOMA2's matrices have a few hundred rows, too small for threads to
        # gain, and on a loaded machine idle threads spin (issue 27: 12 minutes under load; the
        # benchmark's band case 22 → 2 s of CPU at a load of 11 on 2 cores).
        with _PYOMA2_LOOPS, mock.patch.object(loops, "trange", counted), \
                threadpool_limits(limits=1, user_api="blas"):
            setup.run_by_name("ssi")
    finally:
        logger.setLevel(level)
    modes = _from_poles(algorithm.result, names, sample_rate, low, high, n_modes, warn)
    return dataclasses.replace(modes, settings={**settings, "n_blocks": options["n_blocks"],
                                                "frequency_band": [low, high]})


def _from_poles(result, names, sample_rate, low, high, n_modes, warn=True):
    """Group the stable poles into modes and check them (docs: theory, Operational modal
    analysis, from poles to modes)."""
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
        ranked = ranked[support[ranked] >= MIN_STABLE_SHARE * orders_with_poles]
    elif ranked.size < n_modes:
        raise EstimationError(f"only {ranked.size} stable mode(s) in the band, n_modes = "
                              f"{n_modes} asked")
    passing, failing = [], []
    for c in ranked:                                  # best supported first
        p, o = pole[clusters[c]], column[clusters[c]]
        mode = _mode(frequency[p, o], damping[p, o], f_std[p, o], xi_std[p, o], shapes[p, o])
        (failing if mode[-1] else passing).append(mode)
        if n_modes is not None and len(passing) == n_modes:
            break
    # Without n_modes a group failing the checks is dropped; with it, kept only to make up the
    # number asked. Either way it is named.
    kept = passing + ([] if n_modes is None else failing[:n_modes - len(passing)])
    named = failing if n_modes is None else kept[len(passing):]
    if named and warn:
        words = "; ".join(f"{f:.4g} Hz ({', '.join(faults)})" for f, *_, faults in named)
        warnings.warn(f"SSI-cov: {len(named)} group(s) of stable poles fail the checks of a "
                      f"physical mode (numerical or noise poles): {words}; "
                      + ("dropped (give n_modes to keep them)" if n_modes is None else
                         f"reported only because n_modes = {n_modes} asked"),
                      IdentifiabilityWarning, stacklevel=6)
    if not kept:
        raise EstimationError("no group of stable poles passes the checks of a physical mode: "
                              "the record is too short or too noisy for SSI")
    kept.sort(key=lambda mode: mode[0])
    reported = np.array([m[0] for m in kept])
    missed = []
    for c in ranked if n_modes is not None else ():   # without n_modes every such column is kept
        if support[c] < MIN_STABLE_SHARE * orders_with_poles:
            break                                     # best supported first: the rest are less
        p, o = pole[clusters[c]], column[clusters[c]]
        mode = _mode(frequency[p, o], damping[p, o], f_std[p, o], xi_std[p, o], shapes[p, o])
        if not mode[-1] and np.all(np.abs(reported / mode[0] - 1) > PAIRING_TOLERANCE):
            missed.append({"frequency": float(mode[0]), "damping_ratio": float(mode[1]),
                           "orders": int(support[c]), "of_orders": int(orders_with_poles)})
    if missed and warn:
        for column_ in missed:
            # The issue-27 case: a walking-range mode stable in the diagram, not in the result.
            warnings.warn(f"SSI-cov: a column of stable poles at {column_['frequency']:.4g} Hz "
                          f"(stable over {column_['orders']} of {column_['of_orders']} model "
                          f"orders, passing the checks of a physical mode) is not among the "
                          f"{n_modes} mode(s) reported: raise n_modes to "
                          f"{n_modes + len(missed)} to report it, or narrow frequency_band to "
                          f"leave it out", IdentifiabilityWarning, stacklevel=6)
    return ModeIdentification(
        frequencies=np.array([m[0] for m in kept]), damping_ratios=np.array([m[1] for m in kept]),
        frequency_std=np.array([m[2] for m in kept]), damping_std=np.array([m[3] for m in kept]),
        mode_shapes=np.column_stack([m[4] for m in kept]), sensor_names=names,
        sample_rate=sample_rate,
        poles={"frequency": np.where(np.isfinite(frequency), frequency, np.nan),
               "damping": damping, "stable": stable, "orders": orders},
        missed=tuple(missed))


def _mode(f, xi, f_std, xi_std, shapes):
    """(f, ξ, σ_f, σ_ξ, shape, faults) of one group of stable poles (one per model order).

    f and ξ are the medians; the shape is the real part of the pole nearest the median f, +1 at
    its largest component. The propagated std of single poles is erratic at some orders: its
    median over the group, or the scatter over the orders if that is larger. ``faults`` names
    the checks of a physical mode the group fails (docs: theory, Operational modal analysis).
    """
    nearest = np.argmin(np.abs(f - np.median(f)))
    phi = np.real(shapes[nearest])
    phi = phi / phi[np.argmax(np.abs(phi))]
    frequency, damping = np.median(f), np.median(xi)
    sigma_f = max(_median_finite(f_std), f.std(ddof=1) if f.size > 1 else 0.0)
    sigma_xi = max(_median_finite(xi_std), xi.std(ddof=1) if xi.size > 1 else 0.0)
    mac = np.median(np.abs(shapes.conj() @ phi) ** 2
                    / (np.sum(np.abs(shapes) ** 2, axis=1) * (phi @ phi)))
    faults = []
    if mac < MIN_SHAPE_MAC:
        faults.append(f"its shape changes over the orders: median MAC {mac:.2f} < "
                      f"{MIN_SHAPE_MAC}")
    # A real mode may have a poorly resolved damping ratio (erratic σ_ξ at some orders), but
    # not also a frequency scattering over its own half-power band.
    if sigma_xi >= damping and sigma_f >= damping * frequency:
        faults.append(f"neither damping nor frequency resolved: σ_ξ = {sigma_xi / damping:.0%} "
                      f"of ξ = {damping:.3g}, σ_f = {sigma_f:.3g} Hz >= ξf = "
                      f"{damping * frequency:.3g} Hz (its half-power half-width)")
    return frequency, damping, sigma_f, sigma_xi, phi, faults


def _median_finite(values):
    values = values[np.isfinite(values)]
    return float(np.median(values)) if values.size else 0.0


def ambient_response(structure: ModalModel, duration: float, sample_rate: float,
                     load_psd: ArrayLike,
                     rng: int | np.random.Generator | None = None) -> np.ndarray:
    """Ambient accelerations [m/s²] of the empty bridge at its outputs, shape (n_outputs, N).

    Independent white-noise modal loads with one-sided PSD ``load_psd`` [N²/Hz] (one value, or
    one per mode): each modal acceleration is an exact Gaussian record of the PSD
    |ω² H_j(ω)|² S_q / m_j², H_j = 1/(ω_j² − ω² + 2iξ_jω_jω) [CP03] (docs: theory, Operational
    modal analysis), summed through the output shapes. For testing identification.

    Parameters
    ----------
    structure : ModalModel
        The empty bridge.
    duration : float
        Record length [s].
    sample_rate : float
        Sample rate [Hz].
    load_psd : float or array_like
        One-sided PSD of each modal load [N²/Hz], > 0: one value for every mode or one per mode.
    rng : None, int or numpy.random.Generator
        Seed of the record.

    Returns
    -------
    ndarray, shape (n_outputs, n_samples)
        Accelerations [m/s²].

    See Also
    --------
    identify_modes : the modes identified from such records.
    """

    omega = 2 * np.pi * record_frequencies(duration, sample_rate)
    natural = 2 * np.pi * structure.frequencies[:, np.newaxis]
    masses = structure.modal_masses[:, np.newaxis]
    damping = structure.damping_ratios[:, np.newaxis]
    load = check_positive("load_psd", np.broadcast_to(np.asarray(load_psd, dtype=float),
                                                      (structure.n_modes,)), unit="N²/Hz")
    frf = omega**2 / (masses * (natural**2 - omega**2 + 2j * damping * natural * omega))
    modal = gaussian_record(np.abs(frf) ** 2 * load[:, np.newaxis], sample_rate, rng=rng)
    return structure.output_shapes @ modal
