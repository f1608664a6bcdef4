"""``crowdvib modes``'s work on an ambient-test file: the empty bridge's modes by OMA and, if the
file asks, the modal model they make (docs: :ref:`theory-oma`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .._version import __version__
from .results import AsResults, software_versions
from .schema import schema_header
from ..io.ambient import read_ambient
from ..oma.identify import identify_modes
from ..io.modalfiles import read_modal_model

if TYPE_CHECKING:
    from ..models.structure import ModalModel
    from ..oma.modeid import ModeIdentification

__all__ = ["AmbientModes", "identify_ambient"]


@dataclass(frozen=True)
class AmbientModes(AsResults):
    """What ``crowdvib modes`` computes for an ambient-test file (:func:`identify_ambient`).

    Attributes
    ----------
    path : pathlib.Path
        The ambient-test file.
    name : str
    records : list of Record
        One per setup.
    options : dict
        The keyword arguments of :func:`~crowdvib.oma.identify_modes` it used.
    modes : ModeIdentification
        The identified modes (with the cross-check and the setups, if any).
    structure : ModalModel or None
        The modal model of ``[modal_model]`` (None without one).
    seconds : float
        Wall-clock time of the identification [s].
    """

    path: str | Path
    name: str
    records: list
    options: dict
    modes: ModeIdentification
    structure: ModalModel | None
    seconds: float

    def to_dict(self) -> dict:
        """The results ``crowdvib modes`` writes to results.json, without its files, figures and
        warnings; ``inputs`` holds the record(s) and the identification options as used (the
        block rows and model order SSI-cov chose: ``settings``)."""
        return {**schema_header("modes"), "command": "modes", "crowdvib_version": __version__,
                "versions": software_versions(), "ambient": str(self.path), "name": self.name,
                "inputs": self.inputs(), **self.modes.to_dict()}

    def inputs(self) -> dict:
        """The ambient file (``path``; the report shows paths relative to its folder), per setup
        its record (file, sample rate, channels, length) and the identification options."""
        records = {(f"record {s}" if len(self.records) > 1 else "record"): {
            "file": record.source, "sample_rate": record.sample_rate,
            "channel_names": list(record.channel_names), "duration": record.duration,
            "n_samples": record.n_samples} for s, record in enumerate(self.records, start=1)}
        options = {k: v for k, v in self.options.items() if v is not None}
        options.pop("reference_sensors", None)         # the names are under reference_channels
        if len(self.records) > 1:
            options["reference_channels"] = [self.records[0].channel_names[i] for i in
                                             self.options["reference_sensors"][0]]
        # What SSI-cov / EFDD ran with, chosen or given (the first setup's with several).
        options.update(self.modes.settings)
        return {"path": str(Path(self.path).resolve()), "name": self.name, **records,
                "identification": options}


def identify_ambient(path, *, cross_check: bool = False,
                     progress: Callable[[int, int], None] | None = None) -> AmbientModes:
    """Identify the modes of an ambient-test file, without writing anything.

    Parameters
    ----------
    path : str or pathlib.Path
        The ambient-test file (TOML; its format and every key: docs, Case files,
        :ref:`ambient-files`; an example: ``examples/ambient/paper_beam_ambient.toml``).
    cross_check : bool
        Also identify with the other method and compare (as ``cross_check = true``).
    progress : callable, optional
        ``progress(done, total)`` as the identification advances
        (:func:`~crowdvib.oma.identify_modes`).

    Returns
    -------
    AmbientModes
    """
    import time


    name, records, options, spec = read_ambient(path)
    options["cross_check"] = options["cross_check"] or cross_check
    several = len(records) > 1
    started = time.perf_counter()
    modes = identify_modes([r.data for r in records] if several else records[0].data,
                           records[0].sample_rate,
                           sensor_names=([r.channel_names for r in records] if several
                                         else records[0].channel_names), progress=progress,
                           **options)
    structure = None if spec is None else _modal_model(modes, spec)
    return AmbientModes(path, name, records, options, modes, structure,
                        time.perf_counter() - started)


def _modal_model(modes, spec):
    """The ``[modal_model]``: an FE export's modes updated by the identified ones, or stated
    modal masses with coarse shapes."""

    if spec["fe_model"] is not None:
        fe = read_modal_model(spec["fe_model"], width=spec["width"],
                              output_nodes=spec["output_nodes"])
        return modes.modal_model(fe)
    return modes.modal_model(modal_masses=spec["modal_masses"],
                             sensor_positions=spec["sensor_positions"],
                             walkway=spec["walkway"], width=spec["width"])
