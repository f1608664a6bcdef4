"""Identified modes and the cross-check of two identification methods (docs: theory, Operational
modal analysis).

:class:`ModeIdentification` is what :func:`~crowdvib.identify_modes` returns, whichever method
(SSI-cov, EFDD) and however many setups; :class:`ModeCrossCheck` compares it with a second method
on the same record. OMA gives no modal masses: :meth:`ModeIdentification.modal_model` takes them
from an FE model (or a mass the user states).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._estimators import PAPER_ERROR_LEVELS
from .._validation import as_float_array, check_positive
from ..errors import DataError, EstimationError, ParameterError
from ..models.structure import ModalModel

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

__all__ = ["ModeIdentification", "ModeCrossCheck", "compare_identifications",
           "identified_error_levels", "information_bound", "AGREEMENT_LEVEL",
           "PAIRING_TOLERANCE"]

#: Two methods agree on a mode when |difference| <= this many combined standard deviations
#: (the two-sided 95 % level of a normal difference).
AGREEMENT_LEVEL = 1.96
#: Modes of two identifications pair when their frequencies differ by less than this share.
PAIRING_TOLERANCE = 0.05
_METHOD_NAMES = {"ssi-cov": "SSI-cov", "efdd": "EFDD"}


@dataclass(frozen=True)
class ModeIdentification:
    """Modes identified from an ambient record (docs: theory, Operational modal analysis).

    Attributes
    ----------
    frequencies, damping_ratios : ndarray, (n_modes,)
        f_j [Hz] and ξ_j [-]. SSI-cov: medians over the mode's stable poles; EFDD: from the
        zero crossings and the decay of the mode's correlation function; several setups: the
        inverse-variance weighted means over the setups.
    frequency_std, damping_std : ndarray, (n_modes,)
        Standard deviations [Hz], [-]. SSI-cov: the larger of the propagated one and the scatter
        over the orders; EFDD: delete-a-group jackknife over the Welch segments; several setups:
        of the weighted mean, widened by the Birge ratio when the setups disagree.
    mode_shapes : ndarray, (n_sensors, n_modes)
        Real mode shapes at the sensors, +1 at the largest component (several setups: merged by
        rescaling each setup on the reference sensors).
    sensor_names : tuple of str
    sample_rate : float
    poles : dict
        SSI-cov, the stabilisation diagram: ``frequency``, ``damping`` and ``stable`` arrays of
        shape (n_poles, n_orders), and ``orders``. EFDD, the spectrum: ``frequency`` and
        ``singular_values`` (n_frequencies, n_sensors), the peaks searched (``targets`` [Hz])
        and per mode its ``bells`` (first, last frequency [Hz] of the SDOF bell). Empty for
        several setups (see ``setups``).
    method : str
        ``"ssi-cov"`` or ``"efdd"``.
    cross_check : ModeCrossCheck or None
        The second method's modes and their differences from these (``cross_check=True``).
    setups : tuple of ModeIdentification
        Several setups: each setup's own identification (its sensors only); else empty.
    settings : dict
        SSI-cov: the ``block_rows``, ``max_order``, ``n_blocks``, ``decimation`` (SSI ran at
        ``sample_rate / decimation``) and the ``frequency_band`` (chosen or given); EFDD: the
        ``segment_length``, ``mac_threshold``, jackknife ``groups`` and ``frequency_band``.
    missed : tuple of dict
        SSI-cov with ``n_modes``: columns of stable poles that pass the checks of a physical mode
        but are not reported (none within ``PAIRING_TOLERANCE``): ``frequency``,
        ``damping_ratio``, stable over ``orders`` of the ``of_orders`` model orders with
        stable poles (docs: theory, Operational modal analysis, from poles to modes).
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
    cross_check: ModeCrossCheck | None = None
    setups: tuple = ()
    settings: dict = field(default_factory=dict)
    missed: tuple = ()

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

        Parameters
        ----------
        structure : ModalModel, optional
            An FE model whose outputs are the sensors.
        modal_masses : array_like, optional
            Modal masses [kg], one per identified mode, for shapes of 1 at their largest value.
        sensor_positions : array_like, optional
            The sensors' positions along the walkway [m].
        walkway : (float, float), optional
            The walkway's (start, end) [m].
        width : float, optional
            Walkway width [m].
        name : str
            A label for reports.
        """
        if structure is not None:
            return self._paired_with(structure)
        if modal_masses is None or sensor_positions is None or walkway is None or width is None:
            raise ParameterError("modal_model needs structure (an FE ModalModel at the sensors) "
                                 "or modal_masses, sensor_positions, walkway and width: OMA "
                                 "gives no modal masses")
        masses = np.atleast_1d(check_positive(
            "modal_masses", as_float_array("modal_masses", modal_masses), unit="kg")).ravel()
        if masses.size != self.n_modes:
            # One mass for several modes would be a guess for all but one of them.
            modes = ", ".join(f"{f:.4g} Hz" for f in self.frequencies)
            raise ParameterError(f"modal_masses must give one mass per identified mode "
                                 f"({self.n_modes}: {modes}), got {masses.size}")
        x = as_float_array("sensor_positions", sensor_positions, ndim=1)
        start, end = (float(v) for v in walkway)
        order = np.argsort(x)                   # several setups list the references first
        if x.size != self.mode_shapes.shape[0] or np.any(np.diff(x[order]) <= 0) \
                or x.min() <= start or x.max() >= end:
            raise ParameterError(f"sensor_positions must give one distinct position per sensor "
                                 f"({self.mode_shapes.shape[0]}) strictly inside the walkway "
                                 f"[{start:g}, {end:g}] m, got {x.tolist()}")
        stations = np.concatenate([[start], x[order], [end]])
        shapes = np.vstack([np.zeros(self.n_modes), self.mode_shapes[order],
                            np.zeros(self.n_modes)])
        peak = shapes[np.argmax(np.abs(shapes), axis=0), np.arange(self.n_modes)]
        shapes = shapes / peak
        return ModalModel(frequencies=self.frequencies, damping_ratios=self.damping_ratios,
                          modal_masses=masses, positions=stations - start, mode_shapes=shapes,
                          width=width, output_names=tuple(self.sensor_names[i] for i in order),
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
        """Modelling-error levels for :func:`~crowdvib.studies.modelling_error_study`
        from this identification (see :func:`identified_error_levels`).

        Parameters
        ----------
        levels : dict, optional
            The other parameters' levels (default the paper's ``PAPER_ERROR_LEVELS``).
        """
        return identified_error_levels(self.frequencies, self.frequency_std, self.damping_ratios,
                                       self.damping_std, levels)

    def plot_stabilisation(self, ax: "Axes | None" = None) -> "Figure | SubFigure":
        """SSI-cov: the stabilisation diagram (poles per model order, stable ones filled, modes
        marked), or for EFDD the singular values with the SDOF bells shaded (:meth:`plot_spectrum`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        """
        import matplotlib.pyplot as plt

        if self.method == "efdd":
            return self.plot_spectrum(ax)
        if "orders" not in self.poles:
            raise ParameterError("no stabilisation diagram in a merged multi-setup "
                                 "identification: plot one of its setups")
        if ax is None:
            _, ax = plt.subplots(figsize=(7, 4))
        order = np.broadcast_to(self.poles["orders"], self.poles["frequency"].shape)
        stable = self.poles["stable"]
        ax.plot(self.poles["frequency"][~stable], order[~stable], "x", color="0.7", ms=3,
                label="pole")
        ax.plot(self.poles["frequency"][stable], order[stable], "o", color="C0", ms=3,
                label="stable pole")
        for k, f in enumerate(self.frequencies):
            ax.axvline(f, color="C3", lw=0.8, label="identified mode" if k == 0 else None)
        for k, column in enumerate(self.missed):
            ax.axvline(column["frequency"], color="C1", lw=1.2, ls="--",
                       label="stable column not reported" if k == 0 else None)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("model order")
        ax.set_title("SSI-cov stabilisation diagram")
        ax.legend(loc="lower right")
        return ax.figure

    def plot_mode_shapes(self, ax: "Axes | None" = None) -> "Figure | SubFigure":
        """The mode shapes at the sensors (+1 at each mode's largest component): per sensor one
        bar per mode.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7, 4), layout="constrained")
        sensors = np.arange(len(self.sensor_names))
        width = 0.8 / max(self.n_modes, 1)
        for j in range(self.n_modes):
            ax.bar(sensors + (j - (self.n_modes - 1) / 2) * width, self.mode_shapes[:, j], width,
                   label=f"mode {j + 1}: {self.frequencies[j]:.3f} Hz")
        ax.axhline(0.0, color="0.3", lw=0.6)
        ax.set_xticks(sensors, self.sensor_names)
        ax.set_xlabel("sensor")
        ax.set_ylabel("mode shape [-] (1 at its largest)")
        ax.set_title(f"Mode shapes at the sensors ({_METHOD_NAMES.get(self.method, self.method)})")
        ax.legend(loc="best", fontsize="small")
        return ax.figure

    def plot_spectrum(self, ax: "Axes | None" = None) -> "Figure | SubFigure":
        """EFDD: singular values of the output spectral matrix (log scale), bells shaded.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        """
        import matplotlib.pyplot as plt

        if "singular_values" not in self.poles:
            raise ParameterError(f"plot_spectrum needs an EFDD identification, got method "
                                 f"{self.method!r}")
        if ax is None:
            _, ax = plt.subplots(figsize=(7, 4))
        values = self.poles["singular_values"]
        for k in range(values.shape[1]):
            ax.semilogy(self.poles["frequency"], values[:, k], color="C0" if k == 0 else "0.6",
                        lw=1.0 if k == 0 else 0.7, label="singular value 1" if k == 0 else
                        ("other singular values" if k == 1 else None))
        for (low, high), f in zip(self.poles["bells"], self.frequencies):
            ax.axvspan(low, high, color="C1", alpha=0.15)
            ax.axvline(f, color="C3", lw=0.8)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("singular value [(unit)²/Hz]")
        ax.set_title("EFDD: singular values, SDOF bells shaded")
        ax.legend(loc="upper right")
        return ax.figure

    @classmethod
    def from_dict(cls, data: dict) -> ModeIdentification:
        """The identification of :meth:`to_dict` (a ``crowdvib modes`` results.json holds it).

        The stabilisation diagram's poles are not stored: ``poles`` is empty.

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not such a dict.
        """
        try:
            modes = data["modes"]
            column = {key: [mode[key] for mode in modes] for key in
                      ("frequency", "frequency_std", "damping_ratio", "damping_std")}
            shapes = np.array([mode["mode_shape"] for mode in modes], dtype=float).T
            names = tuple(data["sensor_names"])
            return cls(
                frequencies=np.array(column["frequency"], dtype=float),
                damping_ratios=np.array(column["damping_ratio"], dtype=float),
                frequency_std=np.array(column["frequency_std"], dtype=float),
                damping_std=np.array(column["damping_std"], dtype=float),
                mode_shapes=shapes.reshape(len(names), len(modes)), sensor_names=names,
                # NaN for a dict written before the sample rate was stored
                sample_rate=data.get("sample_rate", float("nan")), poles={},
                method=data["method"],
                cross_check=(None if data.get("cross_check") is None
                             else ModeCrossCheck.from_dict(data["cross_check"])),
                setups=tuple(ModeIdentification.from_dict(setup)
                             for setup in data.get("setups", ())),
                settings=dict(data.get("settings", {})),
                missed=tuple(dict(column) for column in data.get("missed", ())))
        except (KeyError, TypeError, ValueError) as error:
            raise DataError(f"ModeIdentification.from_dict: not a mode identification's dict "
                            f"({type(error).__name__}: {error})") from None

    def to_dict(self) -> dict[str, Any]:
        """Per mode f, ξ and their standard deviations, the shapes, the method and, when run,
        the cross-check (JSON-ready)."""
        result: dict[str, Any] = {
            "method": self.method, "sensor_names": list(self.sensor_names),
            "sample_rate": self.sample_rate,
            "modes": [{"frequency": float(self.frequencies[j]),
                       "frequency_std": float(self.frequency_std[j]),
                       "damping_ratio": float(self.damping_ratios[j]),
                       "damping_std": float(self.damping_std[j]),
                       "mode_shape": [float(v) for v in self.mode_shapes[:, j]]}
                      for j in range(self.n_modes)]}
        if self.settings:
            result["settings"] = dict(self.settings)
        if self.missed:
            result["missed"] = [dict(column) for column in self.missed]
        if self.cross_check is not None:
            result["cross_check"] = self.cross_check.to_dict()
        if self.setups:
            result["setups"] = [setup.to_dict() for setup in self.setups]
        return result


@dataclass(frozen=True)
class ModeCrossCheck:
    """A second identification method against the first, mode by mode (docs: theory,
    Operational modal analysis, cross-check).

    Attributes
    ----------
    method : str
        The second method.
    frequencies, damping_ratios, frequency_std, damping_std : ndarray, (n_modes,)
        The second method's values for the first method's modes (NaN where it found none
        within ``PAIRING_TOLERANCE``).
    frequency_difference, damping_difference : ndarray, (n_modes,)
        Second minus first [Hz], [-].
    frequency_z, damping_z : ndarray, (n_modes,)
        The differences in combined standard deviations √(σ₁² + σ₂²).
    mac : ndarray, (n_modes,)
        MAC of the two methods' shapes.
    agree : ndarray of bool, (n_modes,)
        Both |z| <= ``AGREEMENT_LEVEL`` (and the mode found by both).
    other : ModeIdentification
        The second method's own identification.
    """

    method: str
    frequencies: np.ndarray
    damping_ratios: np.ndarray
    frequency_std: np.ndarray
    damping_std: np.ndarray
    frequency_difference: np.ndarray
    damping_difference: np.ndarray
    frequency_z: np.ndarray
    damping_z: np.ndarray
    mac: np.ndarray
    agree: np.ndarray
    other: ModeIdentification

    @classmethod
    def from_dict(cls, data: dict) -> ModeCrossCheck:
        """The cross-check of :meth:`to_dict` (null as NaN).

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not such a dict.
        """
        keys = ("frequency", "frequency_std", "damping_ratio", "damping_std",
                "frequency_difference", "damping_difference", "frequency_z", "damping_z", "mac")
        try:
            modes = data["modes"]
            column = {key: np.array([mode[key] for mode in modes], dtype=float) for key in keys}
            return cls(method=data["method"], frequencies=column["frequency"],
                       damping_ratios=column["damping_ratio"],
                       **{key: column[key] for key in keys[1:] if key != "damping_ratio"},
                       agree=np.array([mode["agree"] for mode in modes], dtype=bool),
                       # None for a dict written before the second identification was stored
                       other=(ModeIdentification.from_dict(data["other"]) if "other" in data
                              else None))
        except (KeyError, TypeError, ValueError) as error:
            raise DataError(f"ModeCrossCheck.from_dict: not a cross-check's dict "
                            f"({type(error).__name__}: {error})") from None

    def to_dict(self) -> dict[str, Any]:
        """Per mode the second method's values, the differences, z and agreement, and the
        second method's own identification (``other``)."""
        def plain(v):
            return float(v) if np.isfinite(v) else None

        return {"method": self.method, "level": AGREEMENT_LEVEL,
                "modes": [{"frequency": plain(self.frequencies[j]),
                           "frequency_std": plain(self.frequency_std[j]),
                           "damping_ratio": plain(self.damping_ratios[j]),
                           "damping_std": plain(self.damping_std[j]),
                           "frequency_difference": plain(self.frequency_difference[j]),
                           "damping_difference": plain(self.damping_difference[j]),
                           "frequency_z": plain(self.frequency_z[j]),
                           "damping_z": plain(self.damping_z[j]),
                           "mac": plain(self.mac[j]), "agree": bool(self.agree[j])}
                          for j in range(self.agree.size)],
                "other": self.other.to_dict()}


def compare_identifications(first: ModeIdentification,
                            second: ModeIdentification) -> ModeCrossCheck:
    """Pair each mode of ``first`` with the nearest-frequency mode of ``second`` (within
    ``PAIRING_TOLERANCE``) and express their differences in combined standard deviations
    (docs: theory, Operational modal analysis, cross-check)."""
    if tuple(first.sensor_names) != tuple(second.sensor_names):
        raise ParameterError(f"the two identifications must share their sensors, got "
                             f"{list(first.sensor_names)} and {list(second.sensor_names)}")
    n = first.n_modes
    pick = np.full(n, -1)
    if second.n_modes:
        gap = np.abs(second.frequencies[np.newaxis, :] / first.frequencies[:, np.newaxis] - 1)
        nearest = np.argmin(gap, axis=1)
        pick = np.where(gap[np.arange(n), nearest] <= PAIRING_TOLERANCE, nearest, -1)
    found = pick >= 0

    def take(values):
        return np.where(found, values[np.maximum(pick, 0)] if values.size else np.nan, np.nan)

    f2, xi2 = take(second.frequencies), take(second.damping_ratios)
    sf2, sxi2 = take(second.frequency_std), take(second.damping_std)
    df, dxi = f2 - first.frequencies, xi2 - first.damping_ratios
    with np.errstate(divide="ignore", invalid="ignore"):
        zf = df / np.hypot(first.frequency_std, sf2)
        zxi = dxi / np.hypot(first.damping_std, sxi2)
    mac = np.full(n, np.nan)
    if found.any():
        both = _mac(first.mode_shapes[:, found], second.mode_shapes[:, pick[found]])
        mac[found] = np.diag(both)
    agree = found & (np.abs(zf) <= AGREEMENT_LEVEL) & (np.abs(zxi) <= AGREEMENT_LEVEL)
    return ModeCrossCheck(method=second.method, frequencies=f2, damping_ratios=xi2,
                          frequency_std=sf2, damping_std=sxi2, frequency_difference=df,
                          damping_difference=dxi, frequency_z=zf, damping_z=zxi, mac=mac,
                          agree=agree, other=second)


def information_bound(frequencies: ArrayLike, damping_ratios: ArrayLike,
                      duration: float) -> tuple[np.ndarray, np.ndarray]:
    """The smallest standard deviations of f and ξ any unbiased estimator reaches from an
    ambient record of ``duration`` [s] (docs: theory, Operational modal analysis, the
    information bound): σ_f = f √(ξ / (2π f T)) and σ_ξ = ξ / √(2π f ξ T) [Au14]_.

    For a well-separated mode under broadband excitation without measurement noise; noise and
    close modes only raise it.
    """
    f = np.asarray(frequencies, dtype=float)
    xi = np.asarray(damping_ratios, dtype=float)
    cycles_damping = 2 * np.pi * f * xi * duration           # 2π f ξ T
    return f * xi / np.sqrt(cycles_damping), xi / np.sqrt(cycles_damping)


def identified_error_levels(frequencies: ArrayLike, frequency_std: ArrayLike,
                            damping_ratios: ArrayLike, damping_std: ArrayLike,
                            levels: Mapping[str, Sequence[float]] | None = None
                            ) -> dict[str, tuple[float, ...]]:
    """Modelling-error levels whose ε_f and ε_ξ come from an identification, not fixed percentages.

    One and two relative standard deviations (σ_f/f, σ_ξ/ξ) of the least certain identified mode
    (docs: theory, Operational modal analysis); the other parameters keep ``levels`` (default the
    paper's ``PAPER_ERROR_LEVELS``).
    """
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


