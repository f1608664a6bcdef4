"""The empty footbridge as a modal model (docs: theory, Conventions, §2.1, §2.7).

A :class:`ModalModel` holds natural frequencies, damping ratios and modal masses, the mode shapes
sampled on the walkway (positions along the deck × lanes across it × modes) and named output
points with their mode-shape rows. It is the bottom layer: everything else reads it, nothing here
reads anything else of crowdvib but the validation helpers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._plausibility import RANGES, derived, implausibility, warn_notes
from .._validation import (as_float_array, check_count, check_damping_ratio, check_non_negative,
                          check_positive, frozen_array, name_indices)
from ..errors import ParameterError

__all__ = ["ModalModel"]


def _trapezoid_weights(points, lower, upper):
    """Quadrature weights of ``points`` for ∫_lower^upper f: trapezoid between the points,
    the end values held constant out to the limits (so a single point gets the whole length)."""
    weights = np.zeros(points.size)
    if points.size > 1:
        gaps = np.diff(points)
        weights[:-1] += gaps / 2
        weights[1:] += gaps / 2
    weights[0] += points[0] - lower
    weights[-1] += upper - points[-1]
    return weights


@dataclass(frozen=True, eq=False)
class ModalModel:
    """Modal model of an empty footbridge.

    Parameters
    ----------
    frequencies : array_like, shape (n_modes,)
        Natural frequencies f_j [Hz], > 0.
    damping_ratios : array_like, shape (n_modes,)
        Modal damping ratios ξ_j [-], as fractions (0.005, not 0.5 %).
    modal_masses : array_like, shape (n_modes,)
        Modal masses m_j = φ_jᵀ M φ_j [kg] for the scaling of ``mode_shapes``: the engaged physical
        mass for shapes scaled to 1 at the antinode, 1 for mass-normalised shapes.
    positions : array_like, shape (n_positions,)
        Stations along the walkway [m], strictly increasing; the walkway runs from the first to the
        last station.
    mode_shapes : array_like, shape (n_positions, n_modes) or (n_lanes, n_positions, n_modes)
        Vertical mode-shape values at the stations, one slice per lane.
    width : float
        Walkway width B [m].
    lanes : array_like, shape (n_lanes,), optional
        Lateral coordinates of the lanes [m], increasing within [0, width]; default one lane at
        mid-width. Several lanes are needed when modes twist the deck.
    output_names : sequence of str
        Names of the output points (accelerometer locations).
    output_shapes : array_like, shape (n_outputs, n_modes)
        Mode-shape rows φ_o at the output points, in the scaling of ``mode_shapes``.
    name : str
        A label for reports.

    See Also
    --------
    ModalModel.simply_supported_beam : the paper's beam in one call.
    crowdvib.read_modal_model : a model from CSV tables or an FE export.
    crowdvib.identify_modes : the modes from ambient records.

    Notes
    -----
    Every formula in crowdvib is invariant to the mode-shape scaling as long as ``modal_masses``
    matches it (docs: theory, Conventions), so FE exports (mass-normalised) and unity-scaled tables give the
    same physics.

    Examples
    --------
    One mode of 2 Hz, 0.5 % damping and 50 t modal mass, sampled at three stations of a
    50 m × 3 m walkway, with an accelerometer at midspan:

    >>> from crowdvib import ModalModel
    >>> bridge = ModalModel(frequencies=[2.0], damping_ratios=[0.005], modal_masses=[50e3],
    ...                     positions=[0.0, 25.0, 50.0], mode_shapes=[[0.0], [1.0], [0.0]],
    ...                     width=3.0, output_names=("midspan",), output_shapes=[[1.0]])
    >>> bridge
    ModalModel('footbridge', 2 Hz, walkway 50 m × 3 m, outputs ['midspan'])
    >>> bridge.n_modes, bridge.area
    (1, 150.0)
    """

    frequencies: np.ndarray
    damping_ratios: np.ndarray
    modal_masses: np.ndarray
    positions: np.ndarray
    mode_shapes: np.ndarray
    width: float
    output_names: tuple
    output_shapes: np.ndarray
    lanes: np.ndarray | None = None
    name: str = "footbridge"
    _area_weights: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        frequencies = check_positive("frequencies", np.atleast_1d(self.frequencies), unit="Hz")
        n_modes = frequencies.size
        damping = check_damping_ratio("damping_ratios", np.atleast_1d(self.damping_ratios),
                                      allow_zero=True)
        masses = check_positive("modal_masses", np.atleast_1d(self.modal_masses), unit="kg")
        for label, array in (("damping_ratios", damping), ("modal_masses", masses)):
            if array.shape != (n_modes,):
                raise ParameterError(
                    f"{label} must have one entry per mode ({n_modes}), got shape {array.shape}")
        positions = as_float_array("positions", self.positions, ndim=1)
        if positions.size < 2 or np.any(np.diff(positions) <= 0):
            raise ParameterError(
                "positions must hold at least 2 strictly increasing stations [m], "
                f"got {positions.size} station(s)" + ("" if positions.size < 2 else
                f", first non-increasing at index {int(np.flatnonzero(np.diff(positions) <= 0)[0]) + 1}"))
        width = check_positive("width", self.width, unit="m")
        shapes = as_float_array("mode_shapes", self.mode_shapes)
        if shapes.ndim == 2:
            shapes = shapes[np.newaxis]
        if shapes.ndim != 3 or shapes.shape[1:] != (positions.size, n_modes):
            raise ParameterError(
                "mode_shapes must have shape (n_positions, n_modes) = "
                f"({positions.size}, {n_modes}) or (n_lanes, {positions.size}, {n_modes}), "
                f"got {np.shape(self.mode_shapes)}")
        silent = np.flatnonzero(~np.any(shapes != 0, axis=(0, 1)))
        if silent.size:     # ∫φ² dA = 0: no walker loads or feels it, its deck mass is m/0
            raise ParameterError(
                f"mode_shapes must not be zero at every station: mode(s) {silent.tolist()} "
                "(walkers can neither load nor feel such a mode; leave it out of the model)")
        lanes = (np.array([width / 2]) if self.lanes is None
                 else check_non_negative("lanes", np.atleast_1d(self.lanes), unit="m"))
        if lanes.shape != (shapes.shape[0],):
            raise ParameterError(
                f"lanes must have one entry per lane of mode_shapes ({shapes.shape[0]}), "
                f"got shape {lanes.shape}")
        if np.any(np.diff(lanes) <= 0) or lanes[-1] > width:
            raise ParameterError(
                f"lanes must increase within [0, width={width:g}] m, got {lanes.tolist()}")
        names = tuple(str(n) for n in self.output_names)
        if len(set(names)) != len(names):
            raise ParameterError(f"output_names must be unique, got {names}")
        outputs = as_float_array("output_shapes", self.output_shapes)
        outputs = outputs.reshape(len(names), -1) if outputs.size else outputs.reshape(0, n_modes)
        if outputs.shape != (len(names), n_modes):
            raise ParameterError(
                f"output_shapes must have shape (n_outputs, n_modes) = ({len(names)}, {n_modes}), "
                f"got {np.shape(self.output_shapes)}")
        weights = np.outer(_trapezoid_weights(lanes, 0.0, width),
                           _trapezoid_weights(positions, positions[0], positions[-1]))
        for name, value in (("frequencies", frequencies), ("damping_ratios", damping),
                            ("modal_masses", masses), ("positions", positions),
                            ("mode_shapes", shapes), ("lanes", lanes),
                            ("output_shapes", outputs), ("_area_weights", weights)):
            object.__setattr__(self, name, frozen_array(value))
        object.__setattr__(self, "width", width)
        object.__setattr__(self, "output_names", names)
        # Once per model, where it is built (a case file, an FE export, the user's code): the
        # estimator and the design check name the same notes again for their verdicts.
        warn_notes(self.implausibilities(), stacklevel=3)

    def __repr__(self):
        f = self.frequencies
        modes = (f"{f[0]:g} Hz" if f.size == 1 else f"{f.size} modes {f[0]:g}–{f[-1]:g} Hz")
        lanes = "" if self.mode_shapes.shape[0] == 1 else f", {self.mode_shapes.shape[0]} lanes"
        return (f"ModalModel({self.name!r}, {modes}, walkway {self.length:g} m × "
                f"{self.width:g} m{lanes}, outputs {list(self.output_names)})")

    # ------------------------------------------------------------------ geometry
    @property
    def n_modes(self) -> int:
        """Number of structural modes."""
        return self.frequencies.size

    @property
    def n_outputs(self) -> int:
        """Number of output points."""
        return len(self.output_names)

    @property
    def length(self) -> float:
        """Walkway length L [m]."""
        return float(self.positions[-1] - self.positions[0])

    @property
    def area(self) -> float:
        """Walkway area A = L·B [m²]."""
        return self.length * self.width

    def implausibilities(self) -> list[str]:
        """Values that are legal but unlikely for a footbridge, with their likely cause.

        The checks of docs: theory, Plausible ranges, all independent of the mode-shape scaling:

        * a damping ratio ξ_j above 0.1 (a percentage given for a fraction: 0.5 meant as 0.5 %);
        * a lowest natural frequency above 10 Hz (rad/s given for Hz);
        * a walkway longer than 1 km or wider than 30 m (millimetres given for metres);
        * an equivalent deck mass m_j / ∫_A φ_j² dA outside 20–1e5 kg/m² (tonnes for kilograms,
          or modal masses that do not match the shapes' scaling).

        The constructor warns (:class:`PlausibilityWarning`) with these notes.

        Returns
        -------
        list of str
            One sentence per doubtful value; empty when all is plausible.
        """
        notes = [implausibility("damping_ratio", ratio, f"damping_ratios[{j}]")
                 for j, ratio in enumerate(self.damping_ratios)]
        notes += [implausibility("lowest_frequency", self.frequencies.min(),
                                 f"frequencies[{int(np.argmin(self.frequencies))}]"),
                  implausibility("length", self.length, "walkway length (positions)"),
                  implausibility("width", self.width, "width")]
        notes = [note for note in notes if note is not None]
        deck = RANGES["deck_mass"]
        mass_per_area = self.modal_masses / np.diag(self.influence_matrix(1.0))
        for j, value in enumerate(mass_per_area):
            if not deck.contains(value):
                notes.append(
                    f"modal_masses[{j}] = {self.modal_masses[j]:g} kg stands for a deck of "
                    f"{value:.3g} kg/m² over the walkway (m_j / ∫φ_j² dA), outside the "
                    f"{deck.low:g}–{deck.high:g} kg/m² of footbridges: tonnes instead of kg, or "
                    "modal masses not in the scaling of the mode shapes?")
        return notes

    def influence_matrix(self, density: float) -> np.ndarray:
        """Crowd-influence matrix Ψ = d ∫_A φ φᵀ dA [persons] (docs: theory, The smeared crowd and the occupied bridge).

        Trapezoidal quadrature along the walkway and across the lanes (outer lanes held constant
        to the deck edges). For a sine mode scaled to 1 and a full deck, Ψ₁₁ = d·L·B/2 = n/2.

        Parameters
        ----------
        density : float
            Pedestrian density d [persons/m²], >= 0.

        Returns
        -------
        ndarray, shape (n_modes, n_modes)
        """
        density = check_non_negative("density", density, unit="persons/m²")
        shapes = self.mode_shapes
        return density * np.einsum("lp,lpi,lpj->ij", self._area_weights, shapes, shapes)

    def shape_integrals(self, absolute: bool = False) -> np.ndarray:
        """∫_A φ_j dA, or ∫_A |φ_j| dA with ``absolute`` [m² × scaling of the shapes].

        The modal force of a unit pressure over the walkway; with ``absolute``, of a unit
        pressure applied with the sign of each mode shape (the design codes' resonant load). Same
        quadrature as :meth:`influence_matrix`.

        Parameters
        ----------
        absolute : bool
            Integrate |φ_j| instead of φ_j.

        Returns
        -------
        ndarray, shape (n_modes,)
        """
        shapes = np.abs(self.mode_shapes) if absolute else self.mode_shapes
        return np.einsum("lp,lpj->j", self._area_weights, shapes)

    def modal_mass_ratios(self, density: float, body_mass: float) -> np.ndarray:
        """Crowd-to-structure modal mass ratios μ_m,j = m_h Ψ_jj / m_j [-] (docs: theory, The smeared crowd and the occupied bridge).

        Parameters
        ----------
        density : float
            Crowd density d [persons/m²].
        body_mass : float
            Mean body mass m_h [kg].

        Returns
        -------
        ndarray, shape (n_modes,)
        """
        body_mass = check_positive("body_mass", body_mass, unit="kg")
        return body_mass * np.diag(self.influence_matrix(density)) / self.modal_masses

    def shapes_at(self, x: ArrayLike, y: ArrayLike | None = None) -> np.ndarray:
        """Mode-shape rows at walkway coordinates, by linear interpolation [scaling of the model].

        Parameters
        ----------
        x : array_like
            Positions along the walkway [m]; outside the walkway the shapes are 0.
        y : array_like, optional
            Lateral positions [m]; default mid-width. Between lanes linear, beyond the outer lanes
            constant.

        Returns
        -------
        ndarray, shape x.shape + (n_modes,)
        """
        x = np.asarray(x, dtype=float)
        y = np.full(x.shape, self.width / 2) if y is None else np.broadcast_to(y, x.shape)
        per_lane = np.stack([
            np.stack([np.interp(x, self.positions, lane[:, j], left=0.0, right=0.0)
                      for j in range(self.n_modes)], axis=-1)
            for lane in self.mode_shapes])
        if self.lanes.size == 1:
            return per_lane[0]
        index = np.clip(np.searchsorted(self.lanes, y) - 1, 0, self.lanes.size - 2)
        low, high = self.lanes[index], self.lanes[index + 1]
        t = np.clip((y - low) / (high - low), 0.0, 1.0)[..., np.newaxis]
        pick = np.arange(x.size).reshape(x.shape)
        lower = per_lane[index, pick]
        upper = per_lane[index + 1, pick]
        return (1 - t) * lower + t * upper

    def output_index(self, names: str | Sequence[str]) -> np.ndarray:
        """Indices of the named outputs; a :class:`ParameterError` lists the known names.

        Parameters
        ----------
        names : str or sequence of str
            Output names.
        """
        return name_indices(names, self.output_names)

    # ------------------------------------------------------------------ variants
    def rescaled(self, factors: ArrayLike) -> ModalModel:
        """The same physics with mode j scaled by ``factors[j]`` (m_j scales by factors[j]²).

        A negative factor flips the sign of a mode; ``1/sqrt(m_j)`` gives mass-normalised shapes.

        Parameters
        ----------
        factors : array_like, shape (n_modes,)
            Scale factor of each mode shape, non-zero.
        """
        factors = as_float_array("factors", np.broadcast_to(factors, (self.n_modes,)))
        if np.any(factors == 0):
            raise ParameterError(f"factors must be non-zero, got {factors.tolist()}")
        with derived():                      # the same physics: checked when self was built
            return self.replace(mode_shapes=self.mode_shapes * factors,
                                output_shapes=self.output_shapes * factors,
                                modal_masses=self.modal_masses * factors**2)

    def mass_normalised(self) -> ModalModel:
        """The same physics with mass-normalised shapes (m_j = 1)."""
        return self.rescaled(1.0 / np.sqrt(self.modal_masses))

    def replace(self, **changes: Any) -> ModalModel:
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes
            Fields of :class:`ModalModel` and their new values.
        """
        fields = dict(frequencies=self.frequencies, damping_ratios=self.damping_ratios,
                      modal_masses=self.modal_masses, positions=self.positions,
                      mode_shapes=self.mode_shapes, width=self.width,
                      output_names=self.output_names, output_shapes=self.output_shapes,
                      lanes=self.lanes, name=self.name)
        fields.update(changes)
        return ModalModel(**fields)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def simply_supported_beam(cls, span: float, width: float, frequency: ArrayLike,
                              damping_ratio: ArrayLike, modal_mass: ArrayLike, n_modes: int = 1,
                              *, n_points: int = 201,
                              outputs: Mapping[str, float | Sequence[float]] | None = None,
                              name: str = "simply supported beam") -> ModalModel:
        """Simply supported beam with sine modes scaled to 1 at their antinode.

        Parameters
        ----------
        span : float
            Span L [m].
        width : float
            Walkway width B [m].
        frequency : float or array_like
            f_1 [Hz] (then f_j = j² f_1, Euler–Bernoulli beam) or one frequency per mode.
        damping_ratio : float or array_like
            ξ_j [-], a fraction, one value or one per mode.
        modal_mass : float or array_like
            Modal mass [kg] of the unity-scaled modes (= half the beam mass for a uniform beam),
            one value or one per mode.
        n_modes : int
            Number of bending modes.
        n_points : int
            Stations along the span for the sampled shapes.
        outputs : dict of str to float, optional
            Output points as name → position along the span [m]; default ``{"midspan": L/2}``.
        name : str
            A label for reports.

        Examples
        --------
        The paper's numerical example (docs: theory, The paper's numerical example):

        >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
        >>> round(float(bridge.influence_matrix(0.5)[0, 0]), 9)   # d B ∫φ² dx = 0.5·3·25
        37.5
        """
        span = check_positive("span", span, unit="m")
        n_modes = check_count("n_modes", n_modes, 1)
        n_points = check_count("n_points", n_points, 3)
        order = np.arange(1, n_modes + 1)
        frequency = np.atleast_1d(as_float_array("frequency", frequency))
        frequencies = frequency[0] * order**2 if frequency.size == 1 else frequency
        outputs = {"midspan": span / 2} if outputs is None else dict(outputs)
        for label, x in outputs.items():
            if not 0.0 <= float(x) <= span:
                raise ParameterError(
                    f"outputs[{label!r}] must lie on the span [0, {span:g}] m, got {x!r}")
        positions = np.linspace(0.0, span, n_points)

        def sine(x):
            return np.sin(np.pi * np.outer(np.asarray(x, dtype=float), order) / span)

        with derived():          # warned below, at the caller's line rather than here
            model = cls(frequencies=frequencies,
                        damping_ratios=np.broadcast_to(damping_ratio, order.shape),
                        modal_masses=np.broadcast_to(modal_mass, order.shape),
                        positions=positions, mode_shapes=sine(positions), width=width,
                        output_names=tuple(outputs),
                        output_shapes=sine(list(outputs.values())), name=name)
        warn_notes(model.implausibilities(), stacklevel=2)
        return model
