"""Several setups of one ambient test, merged (docs: theory, Operational modal analysis, several
setups).

A bridge with more measurement points than sensors is measured in setups: some reference sensors
stay in place, the others rove. Each setup is identified on its own (its shapes have an arbitrary
scale); the shapes are then merged by post-separate estimation re-scaling (PoSER-like, [DLM13]_): every
setup's shape is scaled by the least-squares factor that best maps its reference components onto
those of an anchor setup, and the rescaled rovers are stacked under the averaged references.
Frequencies and damping ratios are the inverse-variance weighted means over the setups.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import DataError, EstimationError, IdentifiabilityWarning, ParameterError
from .modeid import PAIRING_TOLERANCE, ModeIdentification, compare_identifications

__all__ = ["identify_setups", "merge_setups", "REFERENCE_SHARE"]

#: Below this share of the shape's norm on the reference sensors, a setup's rescaling of that
#: mode is ill-conditioned (a reference near a node of the mode): warned.
REFERENCE_SHARE = 0.1


def _signals(name, signals):
    """One setup's signals, checked: a finite (n_sensors, n_samples) array, n_samples >= 100."""
    try:
        data = np.array(signals, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a numeric array (n_sensors, n_samples), got ragged "
                             f"or non-numeric rows") from None
    if data.ndim != 2 or data.shape[0] < 1 or data.shape[1] < 100:
        raise ParameterError(f"{name} must have shape (n_sensors, n_samples) with at least 100 "
                             f"samples, got {data.shape}")
    if not np.all(np.isfinite(data)):
        raise DataError(f"{name} must be finite")
    return data


def _names(sensor_names, count, name):
    names = (tuple(f"sensor_{i + 1}" for i in range(count)) if sensor_names is None
             else tuple(str(n) for n in sensor_names))
    if len(names) != count:
        raise ParameterError(f"{name} must name {count} sensors, got {len(names)}")
    return names


def identify_setups(signals: Sequence, reference_sensors: Sequence[Sequence[int]],
                    sensor_names: Sequence[Sequence[str]] | None,
                    single: Callable[[np.ndarray, tuple], ModeIdentification]
                    ) -> ModeIdentification:
    """Identify every setup with ``single(data, names)`` and merge them (:func:`merge_setups`);
    with a cross-check in every setup, the other method's setups are merged and compared too."""
    if isinstance(signals, np.ndarray) or not isinstance(signals, Sequence) or len(signals) < 2:
        raise ParameterError("signals must be a sequence of at least 2 setups (each an array "
                             "(n_sensors, n_samples)) when reference_sensors is given, got "
                             f"{type(signals).__name__}")
    data = [_signals(f"signals[{s}]", x) for s, x in enumerate(signals)]
    references = _references(reference_sensors, [x.shape[0] for x in data])
    if sensor_names is not None and len(sensor_names) != len(data):
        raise ParameterError(f"sensor_names must give one list of names per setup "
                             f"({len(data)}), got {len(sensor_names)}")
    names = []
    for s, x in enumerate(data):
        default = [f"setup{s + 1}_sensor{i + 1}" for i in range(x.shape[0])]
        for k, i in enumerate(references[s]):
            default[i] = f"reference_{k + 1}"
        names.append(_names(default if sensor_names is None else sensor_names[s], x.shape[0],
                            f"sensor_names[{s}]"))
    shared = [tuple(names[s][i] for i in references[s]) for s in range(len(data))]
    if any(row != shared[0] for row in shared):
        raise ParameterError(f"the reference sensors must have the same names in every setup, "
                             f"got {[list(row) for row in shared]}")
    results = [single(x, n) for x, n in zip(data, names)]
    merged = merge_setups(results, references)
    if all(r.cross_check is not None for r in results):
        others = [r.cross_check.other for r in results if r.cross_check is not None]
        other = merge_setups(others, references, frequencies=merged.frequencies, strict=False)
        merged = dataclasses.replace(merged, cross_check=compare_identifications(merged, other))
    return merged


def _references(reference_sensors, counts):
    try:
        rows = [np.array(row, dtype=int).reshape(-1) for row in reference_sensors]
        ok = all(np.array_equal(np.array(r, dtype=float).reshape(-1), rows[i])
                 for i, r in enumerate(reference_sensors))
    except (TypeError, ValueError):
        ok = False
    if not ok or len(rows) != len(counts):
        raise ParameterError(f"reference_sensors must give per setup ({len(counts)}) the row "
                             f"indices of its reference sensors, got {reference_sensors!r}")
    for s, (row, count) in enumerate(zip(rows, counts)):
        if row.size < 1 or row.size != rows[0].size or np.unique(row).size != row.size \
                or row.min() < 0 or row.max() >= count:
            raise ParameterError(f"reference_sensors[{s}] must hold {rows[0].size} distinct "
                                 f"row indices in [0, {count - 1}] (the same number in every "
                                 f"setup), got {row.tolist()}")
    return rows


def merge_setups(setups: Sequence[ModeIdentification], references: Sequence[np.ndarray], *,
                 frequencies: np.ndarray | None = None, strict: bool = True
                 ) -> ModeIdentification:
    """Merge per-setup identifications (docs: theory, Operational modal analysis, several setups).

    Modes pair by frequency with ``frequencies`` (default the first setup's). A mode missing
    from a setup is an error with ``strict``, else left out of the merged result.
    """
    targets = setups[0].frequencies if frequencies is None else np.asarray(frequencies)
    rows = []
    for j, target in enumerate(targets):
        picks = []
        for s, setup in enumerate(setups):
            gap = (np.abs(setup.frequencies / target - 1) if setup.n_modes
                   else np.array([np.inf]))
            k = int(np.argmin(gap))
            if gap[k] > PAIRING_TOLERANCE:
                if strict:
                    raise EstimationError(f"setup {s + 1} has no mode within "
                                          f"{PAIRING_TOLERANCE:.0%} of {target:.4g} Hz (its "
                                          f"modes: {np.round(setup.frequencies, 4).tolist()})")
                break
            picks.append(k)
        else:
            rows.append(_merged_mode(setups, references, picks, j))
    names = _merged_names(setups, references)
    count = len(names)
    return ModeIdentification(
        frequencies=np.array([r[0] for r in rows]), damping_ratios=np.array([r[1] for r in rows]),
        frequency_std=np.array([r[2] for r in rows]), damping_std=np.array([r[3] for r in rows]),
        mode_shapes=np.column_stack([r[4] for r in rows]) if rows else np.zeros((count, 0)),
        sensor_names=names, sample_rate=setups[0].sample_rate, poles={},
        method=setups[0].method, setups=tuple(setups), settings=setups[0].settings,
        missed=tuple({**column, "setup": s} for s, setup in enumerate(setups, start=1)
                     for column in setup.missed))


def _merged_names(setups, references):
    """The merged sensors: the first setup's (references in place), then the other setups'
    roving sensors; a roving name used in several setups gets " (setup N)"."""
    rovers = [[(i, n) for i, n in enumerate(setup.sensor_names) if i not in set(ref)]
              for setup, ref in zip(setups, references)]
    count = {}
    for row in rovers:
        for _, n in row:
            count[n] = count.get(n, 0) + 1
    shared = {setups[0].sensor_names[i] for i in references[0]}

    def name(n, s):
        return f"{n} (setup {s + 1})" if count[n] > 1 or n in shared else n

    first = list(setups[0].sensor_names)
    for i, n in rovers[0]:
        first[i] = name(n, 0)
    return tuple(first + [name(n, s) for s, row in enumerate(rovers[1:], start=1)
                          for _, n in row])


def _merged_mode(setups, references, picks, j):
    """(f, ξ, σ_f, σ_ξ, merged shape) of one mode from its pick in every setup."""
    shapes = [setup.mode_shapes[:, k] for setup, k in zip(setups, picks)]
    share = np.array([np.linalg.norm(phi[ref]) / np.linalg.norm(phi)
                      for phi, ref in zip(shapes, references)])
    for s in np.flatnonzero(share < REFERENCE_SHARE):
        warnings.warn(f"mode {j + 1}: its reference components in setup {s + 1} hold "
                      f"{share[s]:.1%} of the shape's norm: the setup's rescaling is "
                      f"ill-conditioned (a reference sensor near a node of the mode)",
                      IdentifiabilityWarning, stacklevel=4)
    anchor = shapes[int(np.argmax(share))][references[int(np.argmax(share))]]
    scaled = []
    for phi, ref in zip(shapes, references):
        part = phi[ref]
        scaled.append(phi * (part @ anchor) / (part @ part))
    reference_part = np.mean([phi[ref] for phi, ref in zip(scaled, references)], axis=0)
    first = scaled[0].copy()
    first[references[0]] = reference_part
    merged = [first]
    for phi, ref in zip(scaled[1:], references[1:]):
        merged.append(np.delete(phi, ref))
    shape = np.concatenate(merged)
    shape = shape / shape[np.argmax(np.abs(shape))]
    frequency = _weighted([s.frequencies[k] for s, k in zip(setups, picks)],
                          [s.frequency_std[k] for s, k in zip(setups, picks)])
    damping = _weighted([s.damping_ratios[k] for s, k in zip(setups, picks)],
                        [s.damping_std[k] for s, k in zip(setups, picks)])
    return frequency[0], damping[0], frequency[1], damping[1], shape


def _weighted(values, stds):
    """Inverse-variance weighted mean and its standard deviation, widened by the Birge ratio
    √(χ²/(n − 1)) when the setups scatter more than their standard deviations say."""
    values, stds = np.asarray(values, dtype=float), np.asarray(stds, dtype=float)
    if not np.all(np.isfinite(stds) & (stds > 0)):
        return float(values.mean()), float(values.std(ddof=1) / np.sqrt(values.size))
    weights = 1 / stds**2
    mean = float(np.sum(weights * values) / np.sum(weights))
    std = float(1 / np.sqrt(np.sum(weights)))
    birge = np.sqrt(np.sum(weights * (values - mean) ** 2) / (values.size - 1))
    return mean, std * max(1.0, float(birge))
