"""A self-contained HTML report of a results directory: one file an engineer can send on.

:func:`write_report` reads ``results.json`` (and the figures a command wrote beside it) and writes
``report.html``: inputs, the estimate with its bounds, diagnostics and warnings, figures and
provenance. Figures are embedded as base64 data URIs and the CSS is inline, so the file opens in
any browser without the directory, needs no JavaScript and prints cleanly.

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
  ``psd_convergence.png`` itself;
* provenance: ``command``, ``crowdvib_version``, ``versions``, ``case``, ``case_sha256``, ``seed``,
  ``created``.
"""

import base64
import datetime
import hashlib
import html
import json
from pathlib import Path

import numpy as np

from .. import __version__
from .._files import atomic_path
from ..errors import DataError

__all__ = ["write_report", "render_report", "provenance", "REPORT_NAME", "SECTIONS"]

#: File name of the report inside a results directory.
REPORT_NAME = "report.html"
#: Section ids, in page order (each present in every report).
SECTIONS = ("summary", "estimate", "diagnostics", "figures", "inputs", "provenance")

#: The paper's convergence criterion for a Welch PSD (Fig. 15): ΔG below 10 %.
CONVERGENCE_LEVEL = 0.10
#: J/J_noHSI above this means the MSD explains little of the misfit without HSI. The paper's fits
#: reach below 1 % (Eeklo) and 2 % (Waalse Krook); 10 % leaves room for real data.
RELATIVE_COST_LEVEL = 0.10

_PARAMETERS = (("frequency", "f<sub>h1</sub>", "Hz"), ("damping_ratio", "ξ<sub>h1</sub>", "-"),
               ("mass_ratio", "μ<sub>h1</sub>", "-"))

_CAPTIONS = {
    "psd_fit": "Measured PSD against the model without HSI and with the fitted MSD "
               "(paper Figs. 12, 17, 20).",
    "psd_convergence": "Convergence error ΔG of the Welch PSD with record length; dashed: the "
                       "paper's 10 % (Fig. 15).",
    "objective_map": "Objective J/J<sub>noHSI</sub> over f<sub>h1</sub> and ξ<sub>h1</sub> with "
                     "the optimum; dashed lines, where drawn: nominal ± bound (paper Figs. 4, "
                     "10).",
    "estimation_errors": "Estimation error Δ caused by modelling errors, per perturbed input and "
                         "error level (paper Figs. 11, 19).",
    "parametric_ratios": "Ratio of estimated to true MSD parameters across the family of "
                         "structures; filled circles: optimum on a bound (paper Figs. 5, 6).",
    "psd": "Welch PSD of the simulated record.",
    "time_history": "Simulated acceleration with its 1 s running RMS and the people on the deck.",
}


# ------------------------------------------------------------------------------ public
def write_report(directory, *, results=None):
    """Write ``report.html`` into a results directory, atomically.

    Parameters
    ----------
    directory : str or pathlib.Path
        A directory written by a crowdvib command (holds ``results.json`` and figures).
    results : dict, optional
        The results to report (default: read ``directory/results.json``).

    Returns
    -------
    pathlib.Path
        The report's path.

    Raises
    ------
    DataError
        If the directory or its ``results.json`` is missing or not valid JSON.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise DataError(f"results directory {directory} does not exist")
    if results is None:
        results = _read_results(directory / "results.json")
    text = render_report(results, directory)
    path = directory / REPORT_NAME
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return path


def render_report(results, directory=None):
    """The report as one HTML string.

    Parameters
    ----------
    results : dict
        Contents of a ``results.json``.
    directory : str or pathlib.Path, optional
        Where to find the figures the command wrote (none embedded without it).

    Returns
    -------
    str
    """
    if not isinstance(results, dict):
        raise DataError(f"results must be a JSON object, got {type(results).__name__}")
    directory = None if directory is None else Path(directory)
    notes = _Notes()
    figures = _figures(results, directory, notes)
    diagnostics = _diagnostics_section(results, notes)   # fills notes before the summary
    body = [
        _header(results),
        _nav(),
        _summary_section(results, notes),
        _estimate_section(results),
        diagnostics,
        _figures_section(figures),
        _inputs_section(results),
        _provenance_section(results, directory),
    ]
    title = _e(f"crowdvib {results.get('command', 'results')} — {_case_name(results)}")
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            f'<meta name="generator" content="crowdvib {_e(__version__)}">\n'
            f"<title>{title}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n<main>\n"
            + "\n".join(body) + "\n</main>\n</body>\n</html>\n")


def provenance(case=None):
    """Provenance keys for a ``results.json``, taken when the run starts.

    Parameters
    ----------
    case : str or pathlib.Path, optional
        The case file the run reads (None for an embedded example).

    Returns
    -------
    dict
        ``created`` (UTC, ISO 8601) and ``case_sha256`` (hex digest of the case file, or None):
        recorded at run time they stay true when the case file is edited later.
    """
    created = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    path = None if case is None else Path(case)
    return {"created": created,
            "case_sha256": _sha256(path) if path is not None and path.is_file() else None}


# ------------------------------------------------------------------------------ reading
def _read_results(path):
    if not path.is_file():
        raise DataError(f"{path} does not exist: run a crowdvib command with --out "
                        f"{path.parent} first")
    try:
        results = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise DataError(f"{path} is not valid JSON: {error}") from None
    if not isinstance(results, dict):
        raise DataError(f"{path} must hold a JSON object, got {type(results).__name__}")
    return results


def _get(results, *paths):
    """The first value found along one of the key paths (tuples), else None."""
    for path in paths:
        value = results
        for key in path:
            if not isinstance(value, dict) or key not in value:
                value = None
                break
            value = value[key]
        if value is not None:
            return value
    return None


def _hsi(results, key):
    """An estimator key: top level (demo) or under ``diagnostics`` (estimate)."""
    return _get(results, (key,), ("diagnostics", key))


def _sensitivity(results):
    value = _get(results, ("sensitivity",))
    if value is None and isinstance(results.get("cases"), list):
        value = results
    return value if isinstance(value, dict) and isinstance(value.get("cases"), list) else None


def _summary(results):
    """The sensitivity summary {parameter: {nominal, bound, bound_percent}}, if any."""
    summary = _get(results, ("sensitivity", "summary"), ("summary",))
    return summary if isinstance(summary, dict) else None


def _case_name(results):
    inputs = results.get("inputs")
    if isinstance(inputs, dict) and inputs.get("name"):
        return str(inputs["name"])
    case = results.get("case")
    return Path(str(case)).stem if case else "unnamed case"


# ------------------------------------------------------------------------------ formatting
def _e(value):
    return html.escape(str(value), quote=True)


def _number(value, digits=4):
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(value)
    if isinstance(value, (float, np.floating)):
        if not np.isfinite(value):
            return "—"
        return f"{value:.{digits}g}"
    return _e(value)


def _value(value, depth=0):
    """Compact HTML of a JSON value: long lists summarised, nested dicts as small tables."""
    if isinstance(value, dict):
        if not value:
            return "—"
        if depth >= 2:
            return _e(json.dumps(value, default=str)[:200])
        rows = "".join(f"<tr><th>{_e(_label(k))}</th><td>{_value(v, depth + 1)}</td></tr>"
                       for k, v in value.items())
        return f'<table class="kv">{rows}</table>'
    if isinstance(value, list):
        if not value:
            return "—"
        flat = [v for v in value if isinstance(v, (int, float)) and not isinstance(v, bool)]
        if len(value) > 6 and len(flat) == len(value):
            return (f"{len(value)} values, {_number(min(flat))} … {_number(max(flat))}")
        if len(value) > 6:
            return f"{len(value)} items: " + ", ".join(_value(v, 2) for v in value[:3]) + ", …"
        return ", ".join(_value(v, depth + 1) for v in value)
    return _number(value, 6)


_TITLES = {"hsi": "HSI (MSD model)", "msd": "MSD model", "crowd_used": "crowd used",
           "truth": "truth (MSD of the synthetic measurement)"}


def _label(key):
    return _TITLES.get(str(key), str(key).replace("_", " "))


def _range(value):
    """A [lower, upper] pair as "lower – upper"."""
    if isinstance(value, (list, tuple)) and len(value) == 2:
        return f"{_number(value[0])} – {_number(value[1])}"
    return _value(value)


def _table(header, rows, css=""):
    head = "".join(f"<th>{h}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f'<table class="{css}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


class _Notes:
    """Warnings and confirmations collected while building the sections."""

    def __init__(self):
        self.warnings, self.good = [], []

    def warn(self, text):
        self.warnings.append(text)

    def ok(self, text):
        self.good.append(text)


# ------------------------------------------------------------------------------ sections
def _header(results):
    command = results.get("command", "results")
    return (f'<header><p class="kicker">crowdvib {_e(command)} report</p>'
            f"<h1>{_e(_case_name(results))}</h1>"
            f'<p class="muted">{_e(_get(results, ("inputs", "description")) or "")}</p></header>')


def _nav():
    links = "".join(f'<a href="#{s}">{s.capitalize()}</a>' for s in SECTIONS)
    return f'<nav class="toc">{links}</nav>'


def _summary_section(results, notes):
    estimate = _estimate(results)
    summary = _summary(results)
    items = []
    if estimate:
        for key, symbol, unit in _PARAMETERS[:2]:
            if key in estimate:
                text = f"{symbol} = {_number(estimate[key])}"
                if summary and key in summary and summary[key].get("bound") is not None:
                    text += f" ± {_number(summary[key]['bound'], 2)}"
                items.append(text + ("" if unit == "-" else f" {unit}"))
    relative = _hsi(results, "relative_cost")
    if relative is not None:
        items.append(f"J/J<sub>noHSI</sub> = {_number(relative, 3)}")
    verdict = "".join(f"<li>{item}</li>" for item in items) or "<li>no estimate in these results</li>"
    if notes.warnings:
        box = ('<div class="callout warn"><strong>Check before use</strong><ul>'
               + "".join(f"<li>{w}</li>" for w in notes.warnings) + "</ul></div>")
    else:
        box = ('<div class="callout ok"><strong>No warnings</strong>'
               + ("<ul>" + "".join(f"<li>{g}</li>" for g in notes.good) + "</ul>"
                  if notes.good else "") + "</div>")
    return (f'<section id="summary"><h2>Summary</h2><ul class="headline">{verdict}</ul>'
            f"{box}</section>")


def _estimate(results):
    estimate = results.get("estimate")
    if not isinstance(estimate, dict):
        estimate = _get(results, ("sensitivity", "nominal"), ("nominal",))
    if not isinstance(estimate, dict):
        estimate = _get(results, ("objective_map", "estimate"), ("objective_map", "grid_optimum"))
    return estimate if isinstance(estimate, dict) else None


def _estimate_section(results):
    estimate = _estimate(results)
    parts = ['<section id="estimate"><h2>Estimate</h2>']
    if not estimate:
        parts.append('<p class="muted">These results hold no MSD estimate '
                     f'(command {_e(results.get("command", "?"))}).</p></section>')
        return "".join(parts)
    reference = results.get("truth") or results.get("expected") or {}
    reference_name = "truth" if results.get("truth") else "expected"
    summary = _summary(results) or {}
    bounds = _hsi(results, "bounds") or {}
    active = set(_hsi(results, "active_bounds") or [])
    free = _hsi(results, "free_parameters")
    header = ["parameter", "estimate", "nominal ± bound", reference_name, "error",
              "search bounds"]
    rows = []
    for key, symbol, unit in _PARAMETERS:
        if key not in estimate:
            continue
        value = estimate[key]
        bound = summary.get(key) if isinstance(summary.get(key), dict) else None
        band = (f"{_number(bound['nominal'])} ± {_number(bound['bound'], 3)} "
                f"({_number(bound.get('bound_percent'), 3)} %)" if bound and
                bound.get("bound") is not None else "—")
        truth = reference.get(key) if isinstance(reference, dict) else None
        error = (f"{100 * (value - truth) / truth:+.1f} %" if isinstance(truth, (int, float))
                 and truth and isinstance(value, (int, float)) else "—")
        limits = bounds.get(key)
        limits_text = _range(limits) if isinstance(limits, list) and len(limits) == 2 else "—"
        hits = [a.split(":")[1] for a in active if a.split(":")[0] == key and ":" in a]
        if hits:
            limits_text += f' <span class="badge warn">on {"/".join(hits)} bound</span>'
        fixed = free is not None and key not in free
        name = f"{symbol} [{unit}]" + (' <span class="muted">(fixed)</span>' if fixed else "")
        rows.append([name, f'<span class="num">{_number(value)}</span>', band, _number(truth),
                     error, limits_text])
    parts.append(_table(header, rows, "data"))
    if summary:
        parts.append('<p class="muted">Bounds: the largest estimation error of the joint '
                     "modelling-error cases at the highest error level (the paper's "
                     "“nominal ± bound”).</p>")
    occupied = results.get("occupied_structure")
    if isinstance(occupied, dict) and occupied.get("frequencies"):
        rows = [[f"mode {j + 1}", f"{_number(f)} Hz", f"{100 * x:.2f} %"] for j, (f, x) in
                enumerate(zip(occupied["frequencies"], occupied.get("damping_ratios", [])))]
        parts.append("<h3>Occupied structure with the estimated MSD</h3>"
                     + _table(["", "frequency", "damping ratio"], rows, "data"))
    parts.append("</section>")
    return "".join(parts)


def _diagnostics_section(results, notes):
    rows = []
    cost, no_hsi = _hsi(results, "cost"), _hsi(results, "cost_no_hsi")
    relative = _hsi(results, "relative_cost")
    if relative is not None:
        rows.append(["relative cost J/J<sub>noHSI</sub>", _number(relative, 3)])
        if relative > RELATIVE_COST_LEVEL:
            notes.warn(f"J/J<sub>noHSI</sub> = {_number(relative, 3)} is above "
                       f"{RELATIVE_COST_LEVEL:.0%}: the MSD model explains little of the misfit "
                       "without HSI.")
        else:
            notes.ok(f"the fit removes {100 * (1 - relative):.2f} % of the misfit without HSI "
                     f"(J/J<sub>noHSI</sub> = {_number(relative, 3)}).")
    if cost is not None:
        rows.append(["cost J (paper Eq. 6)", _number(cost, 3)])
    if no_hsi is not None:
        rows.append(["cost without HSI J<sub>noHSI</sub>", _number(no_hsi, 3)])
    success = _hsi(results, "success")
    if success is not None:
        rows.append(["optimiser converged", _number(success)])
        if not success:
            notes.warn(f"the optimiser did not converge: {_e(_hsi(results, 'message') or '')}")
    for key, label in (("n_evaluations", "model evaluations"), ("band", "analysis band [Hz]"),
                       ("output_names", "outputs"), ("output_weights", "output weights γ")):
        value = _hsi(results, key)
        if value is not None:
            rows.append([label, _range(value) if key == "band" else _value(value)])
    active = _hsi(results, "active_bounds")
    if active is not None:
        rows.append(["active bounds", _e(", ".join(active)) if active else "none"])
        if active:
            notes.warn(f"the optimum sits on a bound ({_e(', '.join(active))}): widen the "
                       "bounds or distrust that parameter.")
    parts = ['<section id="diagnostics"><h2>Diagnostics and warnings</h2>']
    if rows:
        parts.append(_table(["quantity", "value"], rows, "data narrow"))
    parts.append(_convergence(results, notes))
    parts.append(_starts(results))
    parts.append(_record_length(results, notes))
    sensitivity = _sensitivity(results)
    if sensitivity:
        failed = [c for c in sensitivity["cases"] if isinstance(c, dict) and "error" in c]
        done = len(sensitivity["cases"]) - len(failed)
        parts.append(f"<p>Modelling-error study: {done} case(s) estimated"
                     + (f", {len(failed)} failed" if failed else "") + ".</p>")
        if failed:
            notes.warn(f"{len(failed)} modelling-error case(s) failed, e.g. "
                       f"{_e(failed[0].get('name', '?'))}: {_e(failed[0]['error'])}")
    messages = results.get("warnings") or []
    for message in messages:
        notes.warn(_e(message))
    if messages:
        parts.append("<h3>Warnings raised during the run</h3><ul>"
                     + "".join(f"<li><code>{_e(m)}</code></li>" for m in messages) + "</ul>")
    elif "warnings" in results:
        parts.append('<p class="muted">No warnings were raised during the run.</p>')
    parts = [part for part in parts if part]
    if len(parts) == 1:
        parts.append('<p class="muted">No diagnostics in these results.</p>')
    parts.append("</section>")
    return "".join(parts)


def _convergence(results, notes):
    convergence = _hsi(results, "convergence")
    if not isinstance(convergence, dict) or "error" not in convergence:
        return ""
    error = np.atleast_2d(np.asarray(convergence["error"], dtype=float))
    duration = np.asarray(convergence.get("duration", []), dtype=float)
    names = convergence.get("output_names") or [f"output {i + 1}" for i in range(len(error))]
    # The last entry is 0 by construction (the full record against itself); the one before is
    # the change that adding the last window made.
    last = error[:, -2] if error.shape[1] > 1 else error[:, 0]
    rows = []
    for name, row, value in zip(names, error, last):
        below = np.flatnonzero(~(row < CONVERGENCE_LEVEL))
        reach = (duration[below[-1] + 1] if below.size and below[-1] + 1 < duration.size
                 else (duration[0] if not below.size and duration.size else None))
        rows.append([_e(name), f"{100 * value:.1f} %",
                     "—" if reach is None else f"{reach:g} s"])
        if value >= CONVERGENCE_LEVEL:
            notes.warn(f"the PSD of {_e(name)} has not converged: the last window changed it "
                       f"by {100 * value:.1f} % (≥ {CONVERGENCE_LEVEL:.0%}); use a longer "
                       "record.")
        else:
            notes.ok(f"PSD of {_e(name)} converged (last change {100 * value:.1f} %).")
    band = convergence.get("band") or ["?", "?"]
    return (f"<h3>PSD convergence ({_e(convergence.get('norm', '2'))}-norm over "
            f"{_range(band)} Hz, T = {_number(convergence.get('window_length'))} s)"
            "</h3>" + _table(["output", "change by the last window",
                              f"ΔG below {CONVERGENCE_LEVEL:.0%} from"], rows, "data narrow"))


def _record_length(results, notes):
    """Table of the estimate against record length (the sensitivity command's second study)."""
    rows = [r for r in results.get("record_length") or [] if isinstance(r, dict)
            and "duration" in r]
    if not rows:
        return ""
    failed = [r for r in rows if "error" in r]
    if failed:
        notes.warn(f"{len(failed)} record-length re-estimation(s) failed, e.g. "
                   f"{_e(failed[0]['error'])}")
    table = [[_number(r["duration"]), _number(r.get("n_windows")), _number(r.get("frequency")),
              _number(r.get("damping_ratio")),
              _number(r.get("delta_frequency"), 3), _number(r.get("delta_damping_ratio"), 3),
              _number(r.get("relative_cost"), 3)] for r in rows if "error" not in r]
    return ("<h3>Estimate against record length</h3>"
            + _table(["record length [s]", "windows", "f<sub>h1</sub> [Hz]", "ξ<sub>h1</sub> [-]",
                      "Δf<sub>h1</sub> [%]", "Δξ<sub>h1</sub> [%]", "J/J<sub>noHSI</sub>"],
                     table, "data"))


def _starts(results):
    starts = _hsi(results, "starts")
    if not isinstance(starts, list) or not starts:
        return ""
    rows = [[_value(s.get("start")), _value(s.get("estimate")), _number(s.get("cost"), 3),
             _number(s.get("n_evaluations")), _number(s.get("status"))]
            for s in starts[:20] if isinstance(s, dict)]
    more = f'<p class="muted">… and {len(starts) - 20} more.</p>' if len(starts) > 20 else ""
    return ("<details open><summary>Starting points of the optimiser</summary>"
            + _table(["start", "estimate", "cost J", "evaluations", "status"], rows, "data")
            + more + "</details>")


def _figures_section(figures):
    parts = ['<section id="figures"><h2>Figures</h2>']
    if not figures:
        parts.append('<p class="muted">No figures in this results directory.</p>')
    for number, (name, mime, data, caption) in enumerate(figures, start=1):
        encoded = base64.b64encode(data).decode("ascii")
        parts.append(f'<figure id="figure-{number}"><img src="data:{mime};base64,{encoded}" '
                     f'alt="{_e(name)}"><figcaption><strong>Figure {number}.</strong> '
                     f'{caption} <span class="muted">({_e(name)})</span></figcaption></figure>')
    parts.append("</section>")
    return "".join(parts)


def _inputs_section(results):
    parts = ['<section id="inputs"><h2>Inputs</h2><div class="cards">']
    shown = 0
    inputs = results.get("inputs")
    blocks = []
    if isinstance(inputs, dict):
        simple = {k: v for k, v in inputs.items() if not isinstance(v, dict)}
        if simple:
            blocks.append(("case", simple))
        blocks += [(k, v) for k, v in inputs.items() if isinstance(v, dict) and v]
    elif results.get("case") is not None:
        blocks.append(("case", {"name": results["case"]}))
    for key in ("truth", "expected", "measured", "record", "crowd_used", "msd", "levels"):
        if isinstance(results.get(key), dict) and not (key == "expected" and isinstance(
                inputs, dict) and inputs.get("expected") == results[key]):
            blocks.append((key, results[key]))
    for key in ("duration", "sample_rate", "rms", "elapsed_s"):
        if key in results:
            blocks.append((key, {key: results[key]}))
    for title, block in blocks:
        parts.append(f'<div class="card"><h3>{_e(_label(title))}</h3>{_value(block)}</div>')
        shown += 1
    if not shown:
        parts.append('<p class="muted">No inputs recorded in these results.</p>')
    parts.append("</div></section>")
    return "".join(parts)


def _provenance_section(results, directory):
    rows = [["command", _e(results.get("command", "—"))],
            ["crowdvib version of the run", _e(results.get("crowdvib_version", "—"))],
            ["crowdvib version of this report", _e(__version__)]]
    versions = results.get("versions")
    if isinstance(versions, dict):
        rows.append(["versions", _e(", ".join(f"{k} {v}" for k, v in versions.items()))])
    case = results.get("case")
    rows.append(["case", _e(case) if case is not None else "—"])
    digest, how = results.get("case_sha256"), "recorded by the run"
    if digest is None and case is not None:
        path = Path(str(case))
        if directory is not None and not path.is_absolute():
            path = directory / path
        if path.is_file():
            digest, how = _sha256(path), "of the file as it is now, when the report was written"
        else:
            how = "no case file (embedded example or file not found)"
    rows.append(["case file SHA-256", (f"<code>{_e(digest)}</code> " if digest else "—")
                 + f'<span class="muted">({_e(how)})</span>'])
    rows.append(["seed", _number(results.get("seed"))])
    created = results.get("created") or results.get("date")
    if created is None and directory is not None and (directory / "results.json").is_file():
        stamp = (directory / "results.json").stat().st_mtime
        created = (datetime.datetime.fromtimestamp(stamp, datetime.timezone.utc)
                   .isoformat(timespec="seconds") + " (time of results.json)")
    rows.append(["run date", _e(created or "—")])
    if directory is not None and (directory / "results.json").is_file():
        rows.append(["results.json SHA-256",
                     f"<code>{_e(_sha256(directory / 'results.json'))}</code>"])
    rows.append(["report written", _e(datetime.datetime.now(datetime.timezone.utc)
                                      .isoformat(timespec="seconds"))])
    return ('<section id="provenance"><h2>Provenance</h2>'
            + _table(["", ""], rows, "data narrow provenance") + "</section>")


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


# ------------------------------------------------------------------------------ figures
def _figures(results, directory, notes):
    """(name, mime type, bytes, caption HTML) of every figure: the files, then data-drawn ones."""
    figures, names = [], []
    if directory is not None:
        listed = [str(n) for n in results.get("figures") or [] if isinstance(n, str)]
        found = sorted(p.name for p in directory.iterdir() if p.suffix.lower() in (".png", ".svg")
                       and not p.name.startswith("."))
        for name in listed:
            if name not in found:
                notes.warn(f"figure {_e(name)} is listed in results.json but missing.")
        for name in dict.fromkeys(n for n in listed + found if n in found):
            data = (directory / name).read_bytes()
            mime = "image/svg+xml" if name.lower().endswith(".svg") else "image/png"
            if mime == "image/png" and not data.startswith(b"\x89PNG\r\n\x1a\n"):
                notes.warn(f"figure {_e(name)} is not a PNG file and is left out.")
                continue
            figures.append((name, mime, data, _caption(name)))
            names.append(Path(name).stem)
    for stem, draw in (("psd_convergence", _draw_convergence), ("objective_map", _draw_map),
                       ("estimation_errors", _draw_errors), ("parametric_ratios", _draw_parametric)):
        if stem in names:
            continue
        try:
            image = draw(results)
        except (KeyError, TypeError, ValueError, IndexError) as error:
            notes.warn(f"the {_e(_label(stem))} figure could not be drawn from results.json: "
                       f"{_e(type(error).__name__)}: {_e(error)}")
            continue
        if image is not None:
            figures.append((f"{stem}.png (drawn from results.json)", "image/png", image,
                            _caption(stem)))
    return figures


def _caption(name):
    stem = Path(name).stem
    if stem in _CAPTIONS:
        return _CAPTIONS[stem]
    if stem.startswith("psd_"):
        return (f"PSD at {_e(stem[4:])}: measured against the model without HSI and with the "
                "fitted MSD (paper Figs. 12, 17, 20).")
    return _e(stem.replace("_", " "))


def _draw_convergence(results):
    from .plotting import figure_bytes, plot_psd_convergence
    from ..signals import PSDConvergence

    data = _hsi(results, "convergence")
    if not isinstance(data, dict) or "error" not in data:
        return None
    convergence = PSDConvergence(
        n_windows=np.asarray(data["n_windows"]), duration=np.asarray(data["duration"], float),
        error=np.atleast_2d(np.asarray(data["error"], float)),
        output_names=tuple(data["output_names"]), window_length=data["window_length"],
        band=tuple(data["band"]), norm=str(data.get("norm", "2")))
    return figure_bytes(plot_psd_convergence(convergence, level=CONVERGENCE_LEVEL))


def _draw_map(results):
    from ..models.pedestrian import MSDModel
    from .plotting import figure_bytes, plot_objective_map
    from ..identification.sensitivity import ObjectiveMap

    data = _get(results, ("objective_map",), ("map",))
    if not isinstance(data, dict) or "cost" not in data:
        return None
    estimate = data.get("estimate") or (results.get("estimate")
                                        if isinstance(results.get("estimate"), dict) else None)
    if estimate:
        estimate = MSDModel(estimate["frequency"], estimate["damping_ratio"],
                            estimate.get("mass_ratio", data.get("mass_ratio", 0.95)))
    cost = np.asarray([[np.nan if v is None else v for v in row] for row in data["cost"]], float)
    objective = ObjectiveMap(frequencies=np.asarray(data["frequencies"], float),
                             damping_ratios=np.asarray(data["damping_ratios"], float), cost=cost,
                             cost_no_hsi=float(data.get("cost_no_hsi") or 0.0),
                             mass_ratio=float(data.get("mass_ratio", 0.95)), estimate=estimate)
    bounds = _hsi(results, "bounds")
    search = bounds if isinstance(bounds, dict) and {"frequency", "damping_ratio"} <= set(bounds) \
        else None
    return figure_bytes(plot_objective_map(objective, uncertainty=_summary(results),
                                           search_bounds=search))


def _draw_errors(results):
    from .plotting import figure_bytes, plot_estimation_errors

    sensitivity = _sensitivity(results)
    if sensitivity is None or not any(isinstance(c, dict) and "delta_frequency" in c
                                      for c in sensitivity["cases"]):
        return None
    return figure_bytes(plot_estimation_errors(sensitivity))


def _draw_parametric(results):
    from .plotting import figure_bytes, plot_parametric_ratios

    data = _get(results, ("parametric",))
    if data is None and isinstance(results.get("rows"), list):
        data = results
    if not isinstance(data, dict) or not any(isinstance(r, dict) and "frequency_ratio" in r
                                             for r in data.get("rows", [])):
        return None
    return figure_bytes(plot_parametric_ratios(data))


# ------------------------------------------------------------------------------ style
_CSS = """
:root { --ink: #1b1f24; --muted: #5b6470; --line: #d9dee4; --accent: #1f4e79;
        --warn-bg: #fff5d6; --warn: #7a5200; --ok-bg: #e8f5ec; --ok: #1d6531; }
* { box-sizing: border-box; }
body { margin: 0; background: #eef0f3; color: var(--ink);
       font: 15px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial,
             sans-serif; }
main { max-width: 1080px; margin: 0 auto; padding: 28px 36px 56px; background: #fff;
       min-height: 100vh; }
header h1 { margin: 0 0 4px; font-size: 1.7em; color: var(--accent); }
.kicker { margin: 0; text-transform: uppercase; letter-spacing: .08em; font-size: .78em;
          color: var(--muted); }
h2 { margin: 34px 0 12px; padding-bottom: 4px; border-bottom: 2px solid var(--line);
     font-size: 1.3em; color: var(--accent); }
h3 { margin: 20px 0 8px; font-size: 1.05em; }
.muted { color: var(--muted); }
nav.toc { display: flex; flex-wrap: wrap; gap: 6px 18px; margin: 14px 0 0; padding: 8px 0;
          border-top: 1px solid var(--line); border-bottom: 1px solid var(--line); }
nav.toc a { color: var(--accent); text-decoration: none; font-weight: 600; font-size: .92em; }
ul.headline { list-style: none; padding: 0; margin: 0 0 12px; display: flex; flex-wrap: wrap;
              gap: 8px 28px; font-size: 1.2em; }
.callout { border-radius: 6px; padding: 10px 14px; margin: 10px 0; }
.callout ul { margin: 6px 0 0; padding-left: 20px; }
.callout.warn { background: var(--warn-bg); color: var(--warn); border-left: 5px solid #e0a800; }
.callout.ok { background: var(--ok-bg); color: var(--ok); border-left: 5px solid #2e9e4f; }
.badge { display: inline-block; padding: 0 6px; border-radius: 4px; font-size: .82em; }
.badge.warn { background: var(--warn-bg); color: var(--warn); border: 1px solid #e0a800; }
table { border-collapse: collapse; margin: 6px 0 12px; font-variant-numeric: tabular-nums; }
table.data { width: 100%; }
table.narrow { width: auto; min-width: 50%; }
th, td { padding: 5px 10px; text-align: left; vertical-align: top; overflow-wrap: anywhere;
         border-bottom: 1px solid var(--line); }
thead th { background: #f3f5f8; font-size: .88em; color: var(--muted); font-weight: 600; }
table.provenance thead { display: none; }
table.kv { width: 100%; margin: 0; font-size: .92em; }
table.kv th { width: 42%; color: var(--muted); font-weight: 500; }
table.kv table.kv th { width: 50%; }
.cards { display: grid; grid-template-columns: repeat(auto-fill, minmax(310px, 1fr));
         gap: 14px; }
.card { border: 1px solid var(--line); border-radius: 6px; padding: 4px 12px 8px; }
.card h3 { margin: 8px 0 4px; text-transform: capitalize; }
figure { margin: 18px 0 26px; }
figure img { display: block; max-width: 100%; height: auto; margin: 0 auto;
             border: 1px solid var(--line); }
figcaption { margin-top: 6px; font-size: .92em; }
details summary { cursor: pointer; font-weight: 600; margin: 12px 0 6px; }
code { font-family: ui-monospace, "SFMono-Regular", Menlo, Consolas, monospace; font-size: .88em;
       overflow-wrap: anywhere; }
@media (max-width: 720px) { main { padding: 16px; } ul.headline { font-size: 1.05em; } }
@page { size: A4; margin: 15mm 13mm; }
@media print {
  body { background: #fff; font-size: 10pt; }
  main { max-width: none; padding: 0; min-height: 0; }
  nav.toc { display: none; }
  h2 { break-after: avoid; page-break-after: avoid; }
  figure, table, .callout, .card { break-inside: avoid; page-break-inside: avoid; }
  figure img { max-height: 120mm; width: auto; border: none; }
  .callout { border: 1px solid #999; }
  details > summary { list-style: none; }
  a { color: inherit; text-decoration: none; }
}
"""
