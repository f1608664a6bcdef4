"""Case files (TOML): the bridge, the crowd and how records are read and processed (arch. §1, §6).

A case file describes one bridge and one crowd, and how its records are read and processed::

    name = "eeklo-like"
    seed = 4                                  # seeds every random draw of `crowdvib simulate`
    force = "zivanovic"                       # walking force: "zivanovic", "young" or "measured"

    [structure]                               # a modal model from CSV files …
    modal_table = "eeklo_like_modes.csv"      #   frequency, damping_ratio, modal_mass per mode
    mode_shapes = "eeklo_like_shapes.csv"     #   position [, lane], one column per mode
    width = 3.0                               #   [m]
    outputs = { main_span = 48.0 }            #   name = position [m] or [x, y]; or
    # output_points = "points.csv"            #   name, one column per mode (the shape rows)
    # type = "simply_supported_beam"          # … or a beam: span, width, frequency, …

    [crowd]        density, walking_speed, step_frequency_mean, step_frequency_std, body_mass,
                   density_uncertainty;
                   counts or density_profile (a CSV: the density against the record's time)
    [hsi]          frequency, damping_ratio, mass_ratio (MSD of `simulate`; μ_h1 of `estimate`)
    [measurement]  files, format, channels, units, sample_rate, time_frame, filter, resample,
                   window_length, overlap, detrend; or several [[measurement]] blocks, each
                   with its own name and [measurement.crowd] (a joint fit of one MSD)
    [estimation]   band, outputs, weights, starts, bounds, free_parameters, match_welch,
                   convergence_norm; [estimation.step_frequencies] cutoff, band, starts, bounds
    [simulation]   duration, sample_rate, warm_up, hsi, record_sample_rate, formats, dtype
    [expected]     the MSD (and step frequencies) a synthetic record was made with
    [design]       codes, density, comfort_class, hsi, weighting, prediction, duration;
                   [design.classes] per code; [design.site_factors] k1–k4 (UK NA);
                   [design.msd] (else [hsi]); [design.damper] (used by `crowdvib check`)
    [comfort]      duration, rms_window, peak_model, output, damper_mass_ratio, …; [traffic]
                   a design table, a daily profile or a CSV (`crowdvib comfort`; casecomfort)
    [report]       client, project, bridge, location, engineer, measurement_date: who the
                   reports are for, shown in the header of every report of the case;
                   template: the consultancy's own page (Jinja2) around the report

Paths are relative to the case file. Every value is checked once here; a bad one raises a
:class:`ParameterError` that names the file and the key, e.g.
``eeklo_like.toml: crowd.density must be > 0, got -0.5``. A case file that cannot be read at all
(missing, a directory, binary, not TOML) is a :class:`DataError` naming it. The key-by-key
reading lives in :mod:`crowdvib.io._toml`; the models' tables in :mod:`crowdvib.io.casemodels`,
the measurements' in :mod:`crowdvib.io.casemeasurement`, ``[design]`` and ``[comfort]`` in
theirs; the records a case names are read by :func:`crowdvib.io.measurement.load_measurement`.
"""

from __future__ import annotations

import datetime
import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .._estimators import METHOD_DEFAULTS
from .._files import template_within
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.loading import ForceModel, YoungForce, ZivanovicForce
from ..models.measured import MeasuredForce
from ..models.pedestrian import MSDModel
from ..models.structure import ModalModel
from ._common import reading
from ._toml import Table, _is_number, read_toml
from .measurement import load_measurement
from .modalfiles import read_modal_model, write_modal_model
from .casecomfort import ComfortSpec, TrafficSpec, _comfort, _traffic
from .casedesign import _design
from .casemodels import _crowd, _crowd_profile, _density_uncertainty, _msd, _structure
from .casespecs import (DesignSpec, EstimationSpec, MeasurementBlock, MeasurementSpec,
                        SimulationSpec, StepFrequencySpec)
from .casemeasurement import _check_profile_frame, _measurements
from .records import RECORD_FORMATS
from ..models.examples import paper_example

__all__ = ["Case", "MeasurementSpec", "MeasurementBlock", "EstimationSpec", "StepFrequencySpec",
           "SimulationSpec", "DesignSpec",
           "load_case", "load_measurement", "read_modal_model", "write_modal_model",
           "paper_example_case", "FORCE_MODELS"]

#: The case file's ``force`` → the walking-force model every command uses (docs: theory, The
#: walking force). "measured" replays the packaged PhysioNet walks (time domain only: simulate).
FORCE_MODELS = {"zivanovic": ZivanovicForce, "young": YoungForce, "measured": MeasuredForce}

# ------------------------------------------------------------------------------------- case
@dataclass(frozen=True, eq=False)
class Case:
    """A case file read and checked: the models and how to process and estimate.

    Attributes
    ----------
    name : str
        The case's name (the file's ``name``, default its stem).
    path : Path
        The case file; record and modal files are relative to its folder.
    structure : ModalModel
        The empty bridge (``[structure]``, or a modal file).
    crowd : Crowd
        The crowd of the record (``[crowd]``).
    msd : MSDModel
        The pedestrians' MSD that simulations and design checks use (``[hsi]``).
    measurement : MeasurementSpec
        Records, channels, units and the Welch and filter settings (``[measurement]``).
    estimation : EstimationSpec
        Band, outputs, method, bounds and interval of the estimate (``[estimation]``).
    simulation : SimulationSpec
        Duration, sample rate and outputs of ``crowdvib simulate`` (``[simulation]``).
    expected : dict
        Known or expected MSD values (``[expected]``), compared with the estimate.
    seed : int or None
        Seed of every random draw the case makes (None: fresh entropy).
    description : str
        Free text about the case.
    not_set : dict
        Dotted keys of :meth:`to_dict` the file did not set → "default" or how they were
        derived.
    design : DesignSpec or None
        The ``[design]`` table (codes, classes, dampers), None without one.
    records : tuple
        The ``[[measurement]]`` blocks of a joint fit (empty for one ``[measurement]`` table).
    force : ForceModel
        The walking-force model (the file's ``force``; default Živanović 2007).
    report : dict
        The ``[report]`` table: who and what the reports are for (client, project, …), text.
    reference_density : float
        The walkers' reference density [persons/m²]: the crowd's density, or for a crowd whose
        density is a profile (``[crowd] counts`` or ``density_profile``; docs: theory, A crowd
        that changes) the file's ``[crowd] density`` or else the profile's mean over its table,
        which set the walkers' speed and step frequency by default and which the commands of a
        stationary crowd (design and comfort checks, mode shapes) take
        (:meth:`stationary_crowd`).
    comfort : ComfortSpec or None
        The ``[comfort]`` table (``crowdvib comfort``), None without one.
    traffic : TrafficSpec or None
        The ``[traffic]`` table: a design table or a daily profile, None without one.

    See Also
    --------
    load_case : reads and checks a case file into a Case.
    crowdvib.estimate_case, crowdvib.check_case, crowdvib.simulate_case
    """

    name: str
    path: Path
    structure: ModalModel
    crowd: Crowd
    msd: MSDModel
    measurement: MeasurementSpec
    estimation: EstimationSpec
    simulation: SimulationSpec
    expected: dict = field(default_factory=dict)
    seed: int = None
    description: str = ""
    #: Dotted keys of :meth:`to_dict` the file did not set → "default" or how they were derived.
    not_set: dict = field(default_factory=dict)
    design: "DesignSpec | None" = None
    #: The ``[[measurement]]`` blocks of a joint fit (empty for one ``[measurement]`` table).
    records: tuple = ()
    #: The walking-force model (the file's ``force``; default Živanović 2007).
    force: ForceModel = field(default_factory=ZivanovicForce)
    #: The ``[report]`` table: who and what the reports are for (client, project, …), text.
    report: dict = field(default_factory=dict)
    #: The walkers' reference density [persons/m²] (the crowd's, or with a profile the file's
    #: ``[crowd] density`` or the profile's mean); None: the crowd's density.
    reference_density: float | None = None
    #: ``[comfort]`` and ``[traffic]`` (``crowdvib comfort``; :mod:`crowdvib.io.casecomfort`).
    comfort: ComfortSpec | None = None
    traffic: TrafficSpec | None = None

    def record_crowd(self) -> Crowd:
        """:attr:`crowd` on the time axis of the record as measured: a profile shifted so that
        t = 0 is the start of ``measurement.time_frame`` (the Welch windows start there); a
        stationary crowd as it is."""
        profile = self.crowd.profile
        if profile is None:
            return self.crowd
        frame = self.measurement.time_frame
        return self.crowd.with_density(profile.shifted(frame[0] if frame else 0.0))

    def stationary_crowd(self) -> Crowd:
        """The walkers at their reference density (:attr:`reference_density`): the crowd of the
        commands that model a stationary crowd (design and comfort checks, mode shapes, the
        step-frequency fit); :attr:`crowd` itself when its density is a number."""
        if self.crowd.profile is None or self.reference_density is None:
            return self.crowd
        return self.crowd.with_density(self.reference_density)

    def blocks(self) -> list[Case]:
        """One case per record: itself, or per ``[[measurement]]`` block the case with that
        block's measurement, crowd and name."""
        if not self.records:
            return [self]
        return [replace(self, name=block.name, measurement=block.measurement,
                        crowd=block.crowd, reference_density=block.reference_density,
                        records=())
                for block in self.records]

    def inputs(self, sections: Sequence[str] | None = None) -> dict[str, Any]:
        """The inputs as a JSON-ready dict (models summarised, paths as strings), as every
        results.json keeps them under ``inputs``; the case itself is its TOML file
        (:func:`load_case`).

        ``sections`` keeps only those tables (e.g. a simulation has no use for ``estimation``);
        ``not_set`` lists the keys the file left to their defaults, for the report to mark.

        Parameters
        ----------
        sections : sequence of str, optional
            The tables to keep (default all).
        """
        def plain(value):
            if isinstance(value, Path):
                return str(value)
            if isinstance(value, (tuple, list)):
                return [plain(v) for v in value]
            if isinstance(value, dict):
                return {k: plain(v) for k, v in value.items()}
            if hasattr(value, "__dataclass_fields__"):
                return {k: plain(getattr(value, k)) for k in value.__dataclass_fields__}
            return value

        s = self.structure
        data = {"name": self.name, "path": None if self.path is None else str(self.path),
                "description": self.description, "seed": self.seed,
                "force": type(self.force).__name__,
                "structure": {"name": s.name, "frequencies": s.frequencies.tolist(),
                              "damping_ratios": s.damping_ratios.tolist(),
                              "modal_masses": s.modal_masses.tolist(), "length": s.length,
                              "width": s.width, "n_lanes": int(s.lanes.size),
                              "output_names": list(s.output_names),
                              "modal_mass_ratios": s.modal_mass_ratios(
                                  self.stationary_crowd().density,
                                  self.crowd.body_mass).tolist()},
                "crowd": _crowd_inputs(self.crowd, self.reference_density),
                "hsi": self.msd.to_dict(),
                "measurement": plain(self.measurement), "estimation": plain(self.estimation),
                "simulation": plain(self.simulation), "expected": dict(self.expected),
                **({} if self.design is None else {"design": plain(self.design)}),
                **({"records": [{"name": block.name, "measurement": plain(block.measurement),
                                 "crowd": _crowd_inputs(block.crowd, block.reference_density)}
                                for block in self.records]} if self.records else {}),
                **{key: plain(getattr(self, key)) for key in ("comfort", "traffic")
                   if getattr(self, key) is not None},
                **({"report": dict(self.report)} if self.report else {})}
        if sections is not None:
            # Every command's report shows the [report] table in its header.
            data = {k: v for k, v in data.items()
                    if not isinstance(v, dict) or k in sections or k == "report"}
        data["not_set"] = {k: v for k, v in self.not_set.items() if k.split(".")[0] in data}
        return data


def _crowd_inputs(crowd, reference_density):
    """A crowd as every command's inputs show it: its fields, the density the walkers'
    reference, and a profile density under ``profile`` (with the crowd)."""
    if crowd.profile is None:
        return crowd.to_dict()
    return dict(crowd.with_density(reference_density).to_dict(),
                profile=crowd.profile.to_dict())


def _bounds(table, keys, rename=None):
    bounds = {}
    for key in keys:
        if table.has(key):
            low, high = table.pair(key)
            if not low > 0:
                raise table.error(key, "must have a lower bound > 0", [low, high])
            bounds[(rename or {}).get(key, key)] = (low, high)
    table.finish()
    return bounds or None


def _starts(table, name, size):
    starts = table.raw(name, None)
    if starts is None:
        return None
    if not (isinstance(starts, list) and all(isinstance(row, list) and all(map(_is_number, row))
                                             for row in starts)):
        raise table.error(name, "must be a list of starting points [[...], ...]", starts)
    array = np.array(starts, dtype=float)
    if array.ndim != 2 or array.shape[1] not in size or array.shape[0] < 1:
        raise table.error(name, f"must be a list of points with {' or '.join(map(str, size))} "
                          "values each", starts)
    return tuple(tuple(row) for row in array.tolist())


def _estimation(table, path):
    band = table.pair("band")
    if band[0] < 0:
        raise table.error("band", "must start at >= 0 Hz", list(band))
    outputs = table.strings("outputs", None)
    weights = table.numbers("weights", None, rule="positive")
    if weights is not None and (outputs is None or weights.size != len(outputs)):
        raise table.error("weights", "must give one weight per entry of estimation.outputs",
                          weights.tolist())
    # Not stated: the estimator's own choice (EstimationSpec.resolved, once the records are known).
    free = table.strings("free_parameters", None)
    steps = {"step_frequency_mean", "step_frequency_std"}
    if free is not None and (set(free) - steps not in ({"frequency", "damping_ratio"},
                                                       {"frequency", "damping_ratio",
                                                        "mass_ratio"})
                             or len(set(free) & steps) == 1):
        raise table.error("free_parameters", "must be [\"frequency\", \"damping_ratio\"] with "
                          "optionally \"mass_ratio\" and optionally both \"step_frequency_mean\" "
                          "and \"step_frequency_std\"", list(free))
    starts = _starts(table, "starts", (2, 3))
    bounds = _bounds(table.table("bounds"), ("frequency", "damping_ratio", "mass_ratio",
                                             "step_frequency_mean", "step_frequency_std"))
    step = None
    if table.has("step_frequencies"):
        sub = table.table("step_frequencies")
        if sub.boolean("enabled", True):
            cutoff = sub.number("cutoff", 2.3, rule="positive")
            step = StepFrequencySpec(
                cutoff=cutoff, band=sub.pair("band", None), starts=_starts(sub, "starts", (2,)),
                bounds=_bounds(sub.table("bounds"), ("mean", "std"),
                               {"mean": "step_frequency_mean", "std": "step_frequency_std"}),
                outputs=sub.strings("outputs", None),
                use_fitted=sub.boolean("use_fitted", True))
        sub.finish()
    spec = EstimationSpec(band=band, outputs=outputs,
                          output_weights=None if weights is None else tuple(weights.tolist()),
                          starts=starts, bounds=bounds, free_parameters=free,
                          match_welch=table.boolean("match_welch", True),
                          convergence_norm=table.string("convergence_norm", "2",
                                                        choices=("2", "inf")),
                          step_frequencies=step,
                          method=table.string("method", None, choices=tuple(METHOD_DEFAULTS)),
                          interval=table.string("interval", "profile",
                                                choices=("profile", "wald", "bootstrap",
                                                         "none")),
                          level=table.number("level", 0.95, rule="positive"),
                          crowd_model=table.string("crowd_model", None,
                                                   choices=("fluctuating", "smeared")),
                          n_boot=table.count("n_boot", 200),
                          check_level=table.boolean("check_level", True))
    if not spec.level < 1:
        raise table.error("level", "must lie in (0, 1) (a fraction, not percent)", spec.level)
    table.finish()
    return spec


def _simulation(table, path):
    formats = table.strings("formats", ("npz",))
    for fmt in formats:
        if fmt not in RECORD_FORMATS:
            raise table.error("formats", f"must list formats among {list(RECORD_FORMATS)}",
                              list(formats))
    spec = SimulationSpec(
        duration=table.number("duration", 600.0, rule="positive"),
        sample_rate=table.number("sample_rate", 100.0, rule="positive"),
        warm_up=table.number("warm_up", 0.0, rule="non_negative"),
        hsi=table.boolean("hsi", True),
        record_sample_rate=table.number("record_sample_rate", None, rule="positive"),
        formats=formats, dtype=table.string("dtype", "float64", choices=("float32", "float64")))
    table.finish()
    return spec


def _expected(table):
    expected = {}
    for key in ("frequency", "damping_ratio", "mass_ratio", "step_frequency_mean",
                "step_frequency_std"):
        value = table.number(key, None, rule="positive")
        if value is not None:
            expected[key] = value
    source = table.string("source", None)
    if source:
        expected["source"] = source
    table.finish()
    return expected


def _report(table):
    """``[report]``: who and what the reports are for, each optional text (only those given).
    The date of the measurement may be a TOML date (``2024-05-01``, kept as ISO text) or any
    text ("spring 2024")."""
    found = {"client": table.string("client", None), "project": table.string("project", None),
             "bridge": table.string("bridge", None), "location": table.string("location", None),
             "engineer": table.string("engineer", None)}
    date = table.raw("measurement_date", None)
    if isinstance(date, datetime.date):             # a TOML date or date-time
        date = date.isoformat()
    if date is not None and not isinstance(date, str):
        raise table.error("measurement_date", "must be a date (2024-05-01) or text", date)
    found["measurement_date"] = date
    template = table.file("template", None)        # a Jinja2 page (crowdvib.reporting.template)
    if template is not None:
        # A case file from someone else names no file of this machine for the report to show:
        # the template lies beside the case file (or below), recorded relative to its folder.
        folder = table.path.parent.resolve()
        template, rule = template_within(folder, table.raw("template"))
        if rule is not None:
            raise table.error("template", rule, table.raw("template"))
        template = template.relative_to(folder).as_posix()
    found["template"] = template
    table.finish()
    return {key: value for key, value in found.items() if value is not None}


def load_case(path: str | os.PathLike) -> Case:
    """Read and check a TOML case file → :class:`Case` (paths relative to the file).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.toml`` case file (``crowdvib init`` writes a commented one).

    Returns
    -------
    Case

    Raises
    ------
    DataError
        A missing, unknown (misspelt) or bad key, and a missing, binary or malformed file; the
        message names the file and the dotted key. (A DataError is also a ParameterError.)
    """
    path = Path(path).resolve()
    data = read_toml(path)
    # One guard: whatever slips past the checks of each key still ends as a DataError naming
    # the case file, never as a foreign traceback.
    with reading(path, "a TOML case"):
        return _case(path, data)


def _case(path, data):
    """The checks of :func:`load_case`, table by table."""
    root = Table(data, "", path)
    name = root.string("name", path.stem)
    description = root.string("description", "")
    seed = root.raw("seed", None)
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise root.error("seed", "must be a non-negative integer", seed)
    force = FORCE_MODELS[root.string("force", "zivanovic", choices=tuple(FORCE_MODELS))]()
    structure = _structure(root.table("structure", required=True), path)
    crowd_table = root.table("crowd", required=True)
    crowd_profile = _crowd_profile(crowd_table, path, structure)
    uncertainty = _density_uncertainty(crowd_table, path)
    crowd, reference_density = _crowd(crowd_table, path, crowd_profile)
    msd = _msd(root.table("hsi"), path)
    measurement, records = _measurements(root, path, crowd, structure)
    estimation = (_estimation(root.table("estimation"), path) if root.has("estimation")
                  else EstimationSpec())
    if not root.has("estimation"):
        root.used.add("estimation")
    estimation = replace(estimation.resolved(joint=len(records) > 1),
                         density_uncertainty=uncertainty)
    simulation = _simulation(root.table("simulation"), path)
    expected = _expected(root.table("expected"))
    design = _design(root.table("design"), path, _msd) if root.has("design") else None
    report = _report(root.table("report"))
    comfort = _comfort(root.table("comfort"), path) if root.has("comfort") else None
    traffic = _traffic(root.table("traffic"), path) if root.has("traffic") else None
    root.finish()
    not_set = _not_set(root.defaulted | ({"estimation"} if not root.has("estimation") else set()))
    outputs = estimation.outputs or structure.output_names
    try:
        structure.output_index(outputs)
    except ParameterError as exc:
        raise ParameterError(f"{path.name}: estimation.{exc}") from None
    if len(records) > 1 and "step_frequency_mean" in estimation.free_parameters:
        raise ParameterError(f"{path.name}: estimation.free_parameters must not hold the step "
                             "frequencies in a joint fit of several [[measurement]] blocks (each "
                             "record has its own crowd: fit its step frequencies first, "
                             "[estimation.step_frequencies])")
    if crowd_profile is not None and records:
        raise ParameterError(
            f"{path.name}: crowd.counts or crowd.density_profile must come with one "
            "[measurement] (the profile is on its record's time), got several [[measurement]] "
            "blocks: give each block's [measurement.crowd] its own counts")
    _check_profile_frame(crowd_profile, measurement, path, "crowd", "one [measurement]")
    for spec in [block.measurement for block in records] or [measurement]:
        if spec.channels is not None:
            try:
                structure.output_index(list(spec.channels))
            except ParameterError as exc:
                raise ParameterError(f"{path.name}: measurement.channels keys: {exc}") from None
    return Case(name=name, path=path, structure=structure, crowd=crowd, msd=msd,
                measurement=measurement, estimation=estimation, simulation=simulation,
                expected=expected, seed=seed, description=description, not_set=not_set,
                design=design, records=records, force=force, report=report,
                reference_density=reference_density, comfort=comfort, traffic=traffic)


#: Case-file keys whose :meth:`Case.inputs` name differs.
_RENAMED = {"measurement.filter.cutoff": "measurement.lowpass_cutoff",
            "measurement.filter.order": "measurement.lowpass_order",
            "estimation.weights": "estimation.output_weights",
            "crowd.density_uncertainty": "estimation.density_uncertainty"}
#: Keys that, when left out, are computed from others rather than defaulted.
_DERIVED = {"crowd.walking_speed": "from the density (Weidmann 1993)",
            "crowd.step_frequency_mean": "from the walking speed (Bruno & Venuti 2009)"}


def _not_set(defaulted):
    """The keys a file left out, as :meth:`Case.inputs` names them → "default" or derivation."""
    # A [report] key left out is not shown, not defaulted.
    return {_RENAMED.get(key, key): _DERIVED.get(key, "default") for key in sorted(defaulted)
            if key.split(".")[0] != "report"}


def paper_example_case():
    """The embedded paper example (docs: theory, The paper's numerical example) as a :class:`Case` without records."""

    example = paper_example()
    return Case(name=example.name, path=None, structure=example.structure, crowd=example.crowd,
                msd=example.msd,
                measurement=MeasurementSpec(window_length=example.window_length),
                estimation=EstimationSpec(band=example.band),
                simulation=SimulationSpec(duration=3600.0, sample_rate=100.0, warm_up=200.0),
                expected=example.msd.to_dict(), seed=20230101,
                description="Van Nimmen & Van den Broeck (2023), numerical example")
