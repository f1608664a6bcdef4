"""A self-contained HTML report of a results directory: one file an engineer can send on.

:func:`write_report` reads ``results.json`` (and the figures a command wrote beside it) and writes
``report.html``: inputs, the estimate with its bounds, diagnostics and warnings, figures and
provenance. Figures are embedded as base64 data URIs and the CSS is inline, so the file opens in
any browser without the directory, needs no JavaScript and prints cleanly. Every value from the
file is escaped (:mod:`crowdvib.reporting.html` builds markup only through autoescaping
templates), and only the figures ``results.json`` names are embedded.

Every section is drawn from the keys present, so the report renders the ``results.json`` of any
command (``demo``, ``estimate``, ``simulate``, ``map``, ``sensitivity``) and tolerates keys it
does not know. Keys it understands (top level, or under ``diagnostics`` for the estimator's):

* ``estimate`` {frequency, damping_ratio, mass_ratio}; ``truth`` or ``expected`` to compare with;
  a sensitivity ``summary`` (under ``sensitivity`` or top level) for nominal ± bound;
* ``cost``, ``cost_no_hsi``, ``relative_cost``, ``success``, ``active_bounds``, ``bounds``,
  ``band``, ``starts``, ``convergence`` (a PSDConvergence dict), ``warnings``;
* ``objective_map`` (an ObjectiveMap dict), ``sensitivity`` (a SensitivityResult dict),
  ``parametric`` (a ParametricResult dict): their figures are drawn here unless the command wrote
  ``objective_map.png``, ``estimation_errors.png``, ``parametric_ratios.png`` or
  ``psd_convergence.png`` itself (listed under ``figures``);
* provenance: ``command``, ``crowdvib_version``, ``versions``, ``case``, ``case_sha256``, ``seed``,
  ``created``.
"""

from pathlib import Path

from .._version import __version__
from .._files import TEMPLATE_SUFFIXES, atomic_path, template_within
from ..errors import terminal_safe
from .._manifest import foreign_files, read_manifest, record_file
from ..cases.results import provenance   # re-exported: results.json's stamp
from ..cases.schema import case_name
from ..cases.verdict import CONVERGENCE_LEVEL, RELATIVE_COST_LEVEL, findings
from ..errors import DataError, ParameterError
from . import sections
from .animation import report_animations
from .comfort_section import comfort_section
from .design_section import design_section
from .figures import collect_figures
from .html import html, page
from .oma_section import modes_section
from .paths import case_folder, without_machine_paths
from .reading import read_results
from .season_section import season_body
from .sections import SECTIONS
from .html import CSS
from .template import BLOCKS, render_template

__all__ = ["write_report", "render_report", "case_template", "provenance", "REPORT_NAME",
           "SECTIONS", "CONVERGENCE_LEVEL", "RELATIVE_COST_LEVEL"]

#: File name of the report inside a results directory.
REPORT_NAME = "report.html"


def write_report(directory, *, results=None, template=None):
    """Write ``report.html`` into a results directory, atomically, and list it in its manifest.

    Parameters
    ----------
    directory : str or pathlib.Path
        A directory written by a crowdvib command (holds ``results.json`` and figures).
    results : Results or dict, optional
        The results to report (default: read ``directory/results.json``).
    template : str or pathlib.Path, optional
        A Jinja2 template of the page (:mod:`crowdvib.reporting.template`), ``.html`` or
        ``.j2``. Default: the template ``results.json`` records, only if it lies inside
        ``directory`` (a received folder's results.json may name any file); else the built-in
        page, saying why. A run passes its case's own (:func:`case_template`).

    Returns
    -------
    pathlib.Path
        The report's path.

    Raises
    ------
    DataError
        If the directory or its ``results.json`` is missing or not valid JSON.
    ParameterError
        If the directory holds a ``report.html`` crowdvib did not write (not in its manifest, or
        changed since): crowdvib does not overwrite it.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise DataError(f"results directory {directory} does not exist")
    path = directory / REPORT_NAME
    if path.exists() or path.is_symlink():
        manifest = read_manifest(directory)
        if manifest is None or REPORT_NAME in foreign_files(directory, manifest):
            raise ParameterError(f"{path} was not written by crowdvib (it is not in "
                                 f"{directory}'s crowdvib manifest, or changed since): crowdvib "
                                 "does not overwrite it; move it away first")
    if results is None:
        results = read_results(directory / "results.json")
    text = render_report(results, directory, template=template)
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    record_file(directory, REPORT_NAME, "report")
    return path


def render_report(results, directory=None, *, template=None):
    """The report as one HTML string.

    Parameters
    ----------
    results : Results or dict
        A result (:func:`crowdvib.load_results`) or the contents of a ``results.json`` (of any
        crowdvib version: keys it lacks are left out).
    directory : str or pathlib.Path, optional
        Where to find the figures ``results["figures"]`` names (none embedded without it).
    template : str or pathlib.Path, optional
        As for :func:`write_report`; a recorded template is looked up in ``directory`` (without
        one, in the case file's folder the results name), and the built-in page is used, saying
        why, where it is not found or not allowed: a report can be rewritten on another machine.

    Returns
    -------
    str
    """
    if hasattr(results, "to_dict"):
        results = results.to_dict()
    if not isinstance(results, dict):
        raise DataError(f"results must be a JSON object, got {type(results).__name__}")
    directory = None if directory is None else Path(directory)
    # Shown without the machine's folders (issue 27 §4); provenance hashes the case file by the
    # path the run recorded.
    shown = without_machine_paths(results, case_folder(results))
    notes, figures, diagnostics = _assess(results, shown, directory)
    recorded = _report_table(results).get("template")
    if template is None and isinstance(recorded, str):
        template = _recorded_template(recorded, directory, results, notes)
    elif template is not None:
        template = Path(template)
        if template.suffix.lower() not in TEMPLATE_SUFFIXES:
            raise ParameterError(f"report template {terminal_safe(template.name)}: must be a "
                                 f"{' or '.join(TEMPLATE_SUFFIXES)} file")
    animations = report_animations(shown)          # issue 38: put in once the page is safe
    body = [
        sections.header(shown),
        sections.nav(shown, animated=bool(animations.pictures)),
        sections.summary_section(shown, notes),
        sections.estimate_section(shown),
        diagnostics,
        sections.figures_section(figures) + animations.slot,
        sections.inputs_section(shown),
        sections.provenance_section(results, directory),
    ]
    if shown.get("command") == "season":        # the season's own blocks (issue 36 §1)
        body = season_body(shown, notes, body)
    title = html("crowdvib {} — {}", shown.get("command", "results"), case_name(shown))
    generator = f"crowdvib {__version__}"
    if template is None:
        return animations.finish(str(page(title, generator, body)))

    return animations.finish(render_template(template, dict(zip(BLOCKS, body)), title=title,
                                             generator=generator, css=CSS,
                                             report=_report_table(shown)))


def case_template(results):
    """The template the case of a run's own ``results`` names (recorded relative to the case
    file's folder), as a path, or None: what the run that just read the case file reports with.
    """
    recorded = _report_table(results).get("template")
    folder = case_folder(results)
    return None if not isinstance(recorded, str) or folder is None else Path(folder) / recorded


def _recorded_template(recorded, directory, results, notes):
    """The template a results.json records, if it may be used; else None, with a note why.

    A results folder may come from someone else: its results.json may name any file
    (``/etc/passwd``). Only a template inside the folder the results are in (the case's
    folder for results held in memory), of a template's suffix, is used; another one only when
    named by the caller (``crowdvib report --template``).
    """
    folder = directory if directory is not None else case_folder(results)
    if folder is None:
        notes.warn(html("the report template {} of the case is not found here: the built-in "
                        "layout is used.", Path(recorded).name))
        return None
    path, rule = template_within(folder, recorded)
    if rule is not None:
        notes.warn(html("the report template {} recorded in the results is not used: a recorded "
                        "template {} (name it with crowdvib report --template to use it); the "
                        "built-in layout is used.", Path(recorded).name, rule))
        return None
    if not path.is_file():
        notes.warn(html("the report template {} of the case is not found here: the "
                        "built-in layout is used.", path.name))
        return None
    return path


def _report_table(results):
    """The case's ``[report]`` table a results dict records (``inputs.report``), or {}."""
    inputs = results.get("inputs")
    table = inputs.get("report") if isinstance(inputs, dict) else None
    return table if isinstance(table, dict) else {}


def _assess(results, shown, directory):
    """The notes (the verdict's findings, then the figures' problems), figures and diagnostics
    section of a results dict; ``shown`` is the dict without machine paths. Figures are looked
    up by the names the run recorded (a name outside the directory is refused, not renamed)."""
    notes = sections.Notes(findings(shown), shown)
    figures = collect_figures(results, directory, notes, CONVERGENCE_LEVEL)
    diagnostics = sections.diagnostics_section(shown)
    diagnostics += design_section(shown)         # crowdvib check only
    diagnostics += modes_section(shown)                    # crowdvib modes only
    diagnostics += comfort_section(shown)                  # crowdvib comfort only
    return notes, figures, diagnostics

