"""The sections of report.html, each drawn from the keys a ``results.json`` holds.

Every function returns :class:`markupsafe.Markup` built with :mod:`crowdvib.reporting.html`,
so values from the file are escaped on the way in.
"""

import base64
import datetime
from pathlib import Path

import numpy as np

from .._version import __version__
from .._files import sha256_file
from ..cases.schema import case_name, estimate, get, hsi, real as _real, sensitivity, summary
from ..cases.verdict import CONVERGENCE_LEVEL, RELATIVE_COST_LEVEL, is_doubt
from .comfort_section import comfort_headline
from .design_section import damper_items, design_decisions, msd_section
from .estimator_section import client_inputs, convergence_norm_words, estimator_details
from .html import Markup, escape, html, join, label, number, span, table, value
from .oma_section import modes_headline
from .paths import relative_path
from .text import interval_of, with_interval

__all__ = ["REPORT_FIELDS", "Notes", "finding_markup", "SECTIONS", "CONVERGENCE_LEVEL", "RELATIVE_COST_LEVEL", "header", "nav", "section_titles", "run_warnings", "summary_section", "verdict_box",
           "estimate_section",
           "diagnostics_section", "figures_section", "inputs_section", "provenance_section"]

#: Section ids, in page order (each present in every report).
SECTIONS = ("summary", "estimate", "diagnostics", "figures", "inputs", "provenance")

_PARAMETERS = (("frequency", Markup("f<sub>h1</sub>"), "Hz"),
               ("damping_ratio", Markup("ξ<sub>h1</sub>"), "-"),
               ("mass_ratio", Markup("μ<sub>h1</sub>"), "-"),
               # fitted with the MSD when the case frees them (docs: theory, Step frequencies
               # fitted with the MSD)
               ("step_frequency_mean", Markup("μ<sub>fs</sub>"), "Hz"),
               ("step_frequency_std", Markup("σ<sub>fs</sub>"), "Hz"))
_RELATIVE = Markup("J/J<sub>noHSI</sub>")


#: Symbols the verdict's plain texts spell out, typeset (after escaping) in the report.
_SYMBOLS = (("J/J_noHSI", _RELATIVE), ("f_h1", Markup("f<sub>h1</sub>")),
            ("ξ_h1", Markup("ξ<sub>h1</sub>")), ("μ_h1", Markup("μ<sub>h1</sub>")))


def finding_markup(text):
    """A verdict's plain text as Markup: escaped, its symbols typeset."""
    text = escape(text)
    for plain, typeset in _SYMBOLS:
        text = Markup(text.replace(plain, typeset))
    return text


def run_warnings(results):
    """Every warning a results dict lists (top level and the estimator's ``diagnostics``), each
    once."""
    found = [hsi(results, "warnings")] + ([results["warnings"]] if "warnings" in results else [])
    return list(dict.fromkeys(str(m) for messages in found if isinstance(messages, list)
                              for m in messages))


class Notes:
    """The verdict's findings (:func:`crowdvib.cases.verdict.findings`) as Markup: the checks the
    bridge fails apart from the tool's doubts about its own result, which hold every warning
    the results list (issue 27 §4: a report never says "No warnings" over listed ones), and the
    report's own warnings about the results directory (a listed figure missing)."""

    def __init__(self, findings=(), results=None):
        findings = list(findings)
        # A code that fails only at the conservative end of the interval is a doubt (the data
        # do not decide it); one the bridge fails at the result is the checks' answer.
        self.fails = [finding_markup(f.text) for f in findings
                      if f.severity == "fail" and not is_doubt(f)]
        self.warnings = [finding_markup(f.text) for f in findings if is_doubt(f)]
        said = {f.text for f in findings}
        self.warnings += [finding_markup(m) for m in run_warnings(results or {})
                          if m not in said]
        self.good = [finding_markup(f.text) for f in findings if f.severity == "ok"]

    def warn(self, text):
        self.warnings.append(html("{}", text))


#: The case file's ``[report]`` keys in the order the header shows them, with their labels.
REPORT_FIELDS = (("client", "Client"), ("project", "Project"), ("bridge", "Bridge"),
                  ("location", "Location"), ("engineer", "Engineer"),
                  ("measurement_date", "Date of measurement"))


def header(results):
    """Title, description and the case's ``[report]`` table (client, project, …; issue 27 §4)."""
    given = get(results, ("inputs", "report"))
    given = given if isinstance(given, dict) else {}
    rows = join(html("<tr><th>{}</th><td>{}</td></tr>", title, given[key])
                for key, title in REPORT_FIELDS if isinstance(given.get(key), str))
    about = html('<table class="kv letterhead">{}</table>', rows) if rows else ""
    return html('<header><p class="kicker">crowdvib {} report</p><h1>{}</h1>'
                '<p class="muted">{}</p>{}</header>', results.get("command", "results"),
                case_name(results), get(results, ("inputs", "description")) or "", about)


def section_titles(results, animated=False):
    """Section id → its title in the table of contents, in page order: a design check shows the
    MSD model it used where an estimate would be; an OMA report has no estimate section;
    ``animated``: the page shows its animations after the figures."""
    titles = {s: s.capitalize() for s in SECTIONS}
    if results.get("command") == "check":
        titles["estimate"] = "MSD model"
    elif results.get("command") == "modes":
        del titles["estimate"]
    elif results.get("command") == "season":     # the joint estimate, then every record
        order = list(SECTIONS)
        order.insert(order.index("estimate") + 1, "records")
        own = {"estimate": "Joint estimate", "records": "Records"}
        titles = {s: own.get(s) or titles[s] for s in order}
    if animated:
        order = list(titles)
        order.insert(order.index("figures") + 1, "animations")
        titles = {s: titles.get(s, "Animations") for s in order}
    return titles


def nav(results=None, animated=False):
    return html('<nav class="toc">{}</nav>',
                join(html('<a href="#{}">{}</a>', s, title)
                     for s, title in section_titles(results or {}, animated).items()))


def summary_section(results, notes):
    found, bounds = estimate(results), summary(results) or {}
    items = []
    for key, symbol, unit in _PARAMETERS[:2] if found else ():
        if key in found and _real(found[key]) is not None:
            text = html("{} = {}", symbol, with_interval(found[key], interval_of(found, key),
                                                          unit))
            if key in bounds and bounds[key].get("bound") is not None:
                text += html("; modelling errors ± {}{}", number(bounds[key]["bound"], 2),
                             "" if unit == "-" else f" {unit}")
            items.append(text)
    relative = hsi(results, "relative_cost")
    if relative is not None:
        items.append(html("{} = {}", _RELATIVE, number(relative, 3)))
    response = _response(results)
    if response is not None:
        items.append(response[0])
    items += design_decisions(results) + damper_items(results) + modes_headline(results)
    items += comfort_headline(results)
    verdict = (join(html("<li>{}</li>", item) for item in items)
               or Markup("<li>no estimate in these results</li>"))
    return html('<section id="summary"><h2>Summary</h2><ul class="headline">{}</ul>{}{}</section>',
                verdict, response[1] if response is not None else "", verdict_box(notes))


def verdict_box(notes, more=Markup("")):
    """The summary's boxes: what the bridge fails (the checks' answer, red) apart from what the
    tool doubts about its own result (check before use, yellow), each in its box and words
    (issue 36 §3), ``more`` (a season's records in doubt) in the doubt's; or "No warnings"."""
    box = (html('<div class="callout fail"><strong>The bridge fails {} design check(s)'
                '</strong><p>The checks\' answer, not a doubt about the result.</p>{}</div>',
                len(notes.fails), _listed(None, notes.fails)) if notes.fails else Markup(""))
    if notes.warnings or more:
        return box + html('<div class="callout warn"><strong>Check before use: the result '
                          'itself is in doubt</strong>{}{}</div>',
                          _listed("The tool doubts its result: {} warning(s)", notes.warnings),
                          more)
    good = (html("<ul>{}</ul>", join(html("<li>{}</li>", g) for g in notes.good))
            if notes.good else "")
    return box + html('<div class="callout ok"><strong>{}</strong>{}</div>',
                      "The result itself is not in doubt: no warnings" if notes.fails
                      else "No warnings", good)


def _listed(heading, items):
    if not items:
        return Markup("")
    listed = html("<ul>{}</ul>", join(html("<li>{}</li>", item) for item in items))
    return listed if heading is None else html("<p>{}:</p>{}", html(heading, len(items)), listed)


def _response(results):
    """(headline, table) of a simulated response: RMS, peak and largest running RMS per output
    in m/s², or None when the results hold none."""
    data = results.get("response")
    if not isinstance(data, dict) or not isinstance(data.get("output_names"), list):
        return None
    names = data["output_names"]
    columns = [data.get(k) if isinstance(data.get(k), list) and len(data[k]) == len(names)
               else [None] * len(names) for k in ("rms", "peak", "max_running_rms")]
    window = number(data.get("running_rms_window"))
    rows = [[name, *(number(_real(c[i]), 3) for c in columns)] for i, name in enumerate(names)]
    running = [(_real(v), name) for v, name in zip(columns[2], names) if _real(v) is not None]
    headline = (html("largest {} s running RMS = {} m/s² (at {})", window,
                     number(max(running)[0], 3), max(running)[1]) if running
                else Markup("simulated response (no running RMS)"))
    return headline, table(["output", "RMS [m/s²]", "peak |a| [m/s²]",
                            html("largest {} s running RMS [m/s²]", window)], rows)


def _combined(results, key):
    """[low, high] of the statistical interval widened by the modelling bound, if recorded."""
    row = (results.get("combined") or {}).get(key) if isinstance(results.get("combined"),
                                                                  dict) else None
    ends = row.get("combined") if isinstance(row, dict) else None
    if isinstance(ends, list) and len(ends) == 2 and all(_real(v) is not None for v in ends):
        return ends
    return None


def estimate_section(results):
    """The estimate; the MSD a design check used; nothing for an OMA report."""
    if "estimate" not in section_titles(results):
        return Markup("")
    used = msd_section(results)
    if used is not None:
        return used
    found = estimate(results)
    if not found:
        return html('<section id="estimate"><h2>Estimate</h2><p class="muted">These results '
                    "hold no MSD estimate (command {}).</p></section>",
                    results.get("command", "?"))
    reference = results.get("truth") or results.get("expected") or {}
    reference_name = "truth" if results.get("truth") else "expected"
    bounds_summary = summary(results) or {}
    bounds = hsi(results, "bounds")
    bounds = bounds if isinstance(bounds, dict) else {}
    active = [a for a in hsi(results, "active_bounds") or [] if isinstance(a, str)]
    free = hsi(results, "free_parameters")
    rows = []
    for key, symbol, unit in _PARAMETERS:
        if key not in found:
            continue
        estimate_value = found[key]
        bound = bounds_summary.get(key)
        band = (html("{} ± {} ({} %)", number(bound.get("nominal")),
                     number(bound["bound"], 3), number(bound.get("bound_percent"), 3))
                if bound and bound.get("bound") is not None else "—")
        together = _combined(results, key)
        if together is not None:
            band = html("{}; with the interval: {}–{}", band, number(together[0], 3),
                        number(together[1], 3))
        truth = reference.get(key) if isinstance(reference, dict) else None
        error = (f"{100 * (estimate_value - truth) / truth:+.1f} %"
                 if _real(truth) and _real(estimate_value) is not None else "—")
        limits = bounds.get(key)
        limits_text = span(limits) if isinstance(limits, list) and len(limits) == 2 else "—"
        hits = [a.split(":")[1] for a in sorted(set(active))
                if a.split(":")[0] == key and ":" in a]
        if hits:
            limits_text = html('{} <span class="badge warn">on {} bound</span>', limits_text,
                               "/".join(hits))
        fixed = isinstance(free, list) and key not in free
        name = html("{} [{}]{}", symbol, unit,
                    Markup(' <span class="muted">(fixed)</span>') if fixed else "")
        ends = interval_of(found, key)
        statistical = (html("{}–{}", number(ends[0], 3), number(ends[1], 3)) if ends else "—")
        rows.append([name, html('<span class="num">{}</span>', number(estimate_value)),
                     statistical, band, number(truth), error, limits_text])
    level = next((interval_of(found, k)[2] for k, _, _ in _PARAMETERS
                  if interval_of(found, k)), 0.95)
    headers = ["parameter", "estimate", f"{100 * level:g} % interval", "nominal ± bound",
               reference_name, "error", "search bounds"]
    # A field estimate has no modelling-error study nor truth: those columns go, not left
    # empty (issue 36 §3).
    keep = [i for i, header in enumerate(headers)
            if i not in (3, 4, 5) or any(str(row[i]) != "—" for row in rows)]
    parts = [table([headers[i] for i in keep], [[row[i] for i in keep] for row in rows],
                   "data")]
    if any(interval_of(found, k) for k, _, _ in _PARAMETERS):
        parts.append(_interval_note(results))
    if bounds_summary:
        parts.append(Markup('<p class="muted">Bounds: the largest estimation error of the joint '
                            "modelling-error cases at the highest error level (the paper's "
                            "“nominal ± bound”). With the interval: the statistical interval "
                            "widened on each side by the bound (the bound is a worst case, not a "
                            "standard deviation, so the two add), kept within the search "
                            "bounds.</p>"))
    occupied = results.get("occupied_structure")
    if isinstance(occupied, dict) and isinstance(occupied.get("frequencies"), list):
        rows = [[f"mode {j + 1}", html("{} Hz", number(f)), html("{} %", number(
            100 * x if _real(x) is not None else None, 3))]
                for j, (f, x) in enumerate(zip(occupied["frequencies"],
                                               occupied.get("damping_ratios") or []))]
        parts.append(html("<h3>Occupied structure with the estimated MSD</h3>{}",
                          table(["", "frequency", "damping ratio"], rows, "data")))
    return html('<section id="estimate"><h2>Estimate</h2>{}</section>', join(parts))


#: What each interval method is, in words (``estimate.interval.method``).
_INTERVALS = {"profile": "profile interval calibrated for the Welch scatter and the correlation "
                         "of neighbouring bins",
              "wald": "Wald interval of the sandwich covariance, which holds the Welch scatter "
                      "and the correlation of neighbouring bins",
              "bootstrap": "percentile bootstrap interval of refits to records drawn from the "
                           "fitted model"}


def _records_held(results):
    """How many records an estimate rests on: a joint fit's (``records``: a season's rows in
    its joint estimate), else one."""
    rows = results.get("records")
    if not isinstance(rows, list):
        return 1
    if results.get("command") == "season":
        return sum(1 for row in rows if isinstance(row, dict) and row.get("in_joint"))
    return len(rows) or 1


def _interval_note(results):
    """What the interval holds: the record's Welch scatter and, when one was stated, the crowd
    density's uncertainty, with the share of each parameter's variance it makes and how far a
    density stated 10 % high moves the estimate (docs: theory, The crowd density's
    uncertainty)."""
    density = hsi(results, "density")
    density = density if isinstance(density, dict) else {}
    stated = _real(density.get("uncertainty"))
    moves = density.get("sensitivity") if isinstance(density.get("sensitivity"), dict) else {}
    shares = (density.get("variance_share") if isinstance(density.get("variance_share"), dict)
              else {})
    held = (html("the uncertainty of the stated crowd density (±{} %, one standard deviation)",
                 number(100 * stated, 3)) if stated else
            Markup("not the crowd density's uncertainty (the density was taken as exact)"))
    ends = (estimate(results) or {}).get("interval")
    method = ends.get("method") if isinstance(ends, dict) else None
    records = _records_held(results)
    parts = [html('<p class="muted">Interval: the statistical uncertainty of {} ({}; docs: '
                  "theory, Statistical uncertainty of an estimate) and {}. It does not hold "
                  "the modelling errors, {}.</p>",
                  "this record" if records == 1
                  else f"the joint fit of {records} records, each with its crowd",
                  _INTERVALS.get(method, _INTERVALS["profile"]), held,
                  "which the nominal ± bound column shows" if summary(results) else
                  "which crowdvib sensitivity estimates (the nominal ± bound)")]
    rows = [[html("{} [{}]", symbol, unit),
             html("{} %", number(100 * shares[key], 2)) if _real(shares.get(key)) is not None
             else "—",
             number(0.1 * moves[key], 3) if _real(moves.get(key)) is not None else "—"]
            for key, symbol, unit in _PARAMETERS if key in moves]
    if rows:
        parts.append(html("<p>How much the crowd density weighs (docs: theory, The crowd "
                          "density's uncertainty):</p>{}", table(
                              ["parameter", "share of the interval's variance from the density",
                               "move of the estimate for a density stated 10 % high"],
                              rows, "data narrow")))
    return join(parts)


def diagnostics_section(results):
    rows = []
    cost, no_hsi = hsi(results, "cost"), hsi(results, "cost_no_hsi")
    relative = hsi(results, "relative_cost")
    if relative is not None:
        rows.append([html("relative cost {}", _RELATIVE), number(relative, 3)])
    if cost is not None:
        likelihood = hsi(results, "method") == "likelihood"
        rows.append(["estimator", "Whittle likelihood of the Welch ordinates" if likelihood
                     else "normalised least squares (paper Eq. 6)"])
        rows.append(["misfit at the estimate (deviance D)" if likelihood
                     else "cost J (paper Eq. 6)", number(cost, 3)])
    if no_hsi is not None:
        rows.append([html("cost without HSI J<sub>noHSI</sub>"), number(no_hsi, 3)])
    success = hsi(results, "success")
    if success is not None:
        rows.append(["optimiser converged", number(success)])
    for key, text in (("n_evaluations", "model evaluations"), ("band", "analysis band [Hz]"),
                      ("output_names", "outputs"), ("output_weights", "output weights γ")):
        found = hsi(results, key)
        if found is not None:
            rows.append([text, span(found) if key == "band" else value(found)])
    active = hsi(results, "active_bounds")
    if isinstance(active, list):
        names = ", ".join(str(a) for a in active)
        rows.append(["active bounds", names or "none"])
    parts = []
    if rows:
        parts.append(table(["quantity", "value"], rows, "data narrow"))
    parts += [_convergence(results), estimator_details(results), _record_length(results)]
    study = sensitivity(results)
    if study:
        cases = [c for c in study["cases"] if isinstance(c, dict)]
        failed = [c for c in cases if "error" in c]
        parts.append(html("<p>Modelling-error study: {} case(s) estimated{}.</p>",
                          len(cases) - len(failed),
                          f", {len(failed)} failed" if failed else ""))
    messages = run_warnings(results)
    if messages:
        parts.append(html("<h3>Warnings raised during the run ({})</h3><ul>{}</ul>",
                          len(messages),
                          join(html("<li><code>{}</code></li>", m) for m in messages)))
    elif "warnings" in results:
        parts.append(Markup('<p class="muted">No warnings were raised during the run.</p>'))
    parts = [part for part in parts if part]
    if not parts:
        parts.append(Markup('<p class="muted">No diagnostics in these results.</p>'))
    return html('<section id="diagnostics"><h2>Diagnostics and warnings</h2>{}</section>',
                join(parts))


def _convergence(results):
    """The convergence table (the verdict judges it: :mod:`crowdvib.cases.verdict`)."""
    convergence = hsi(results, "convergence")
    if not isinstance(convergence, dict) or "error" not in convergence:
        return ""
    try:
        error = np.atleast_2d(np.asarray(convergence["error"], dtype=float))
        duration = np.asarray(convergence.get("duration", []), dtype=float)
    except (TypeError, ValueError):
        return ""
    names = convergence.get("output_names")
    names = names if isinstance(names, list) else [f"output {i + 1}" for i in range(len(error))]
    # The last entry is 0 by construction (the full record against itself); the one before is
    # the change that adding the last window made.
    last = error[:, -2] if error.shape[1] > 1 else error[:, 0]
    rows = []
    for name, row, change in zip(names, error, last):
        below = np.flatnonzero(~(row < CONVERGENCE_LEVEL))
        reach = (duration[below[-1] + 1] if below.size and below[-1] + 1 < duration.size
                 else (duration[0] if not below.size and duration.size else None))
        rows.append([name, f"{100 * change:.1f} %", "—" if reach is None else f"{reach:g} s"])
    band = convergence.get("band") or ["?", "?"]
    return html("<h3>PSD convergence ({} over {} Hz, Welch window T = {} s)</h3>{}",
                convergence_norm_words(convergence.get("norm", "2")), span(band),
                number(convergence.get("window_length")),
                table(["output", "change by the last window",
                       f"ΔG below {CONVERGENCE_LEVEL:.0%} from"], rows, "data narrow"))


def _record_length(results):
    """Table of the estimate against record length (the sensitivity command's second study)."""
    rows = results.get("record_length")
    rows = [r for r in rows if isinstance(r, dict) and "duration" in r] \
        if isinstance(rows, list) else []
    if not rows:
        return ""
    cells = [[number(r["duration"]), number(r.get("n_windows")), number(r.get("frequency")),
              number(r.get("damping_ratio")), number(r.get("delta_frequency"), 3),
              number(r.get("delta_damping_ratio"), 3), number(r.get("relative_cost"), 3)]
             for r in rows if "error" not in r]
    return html("<h3>Estimate against record length</h3>{}", table(
        ["record length [s]", "windows", Markup("f<sub>h1</sub> [Hz]"),
         Markup("ξ<sub>h1</sub> [-]"), Markup("Δf<sub>h1</sub> [%]"),
         Markup("Δξ<sub>h1</sub> [%]"), _RELATIVE], cells, "data"))


def figures_section(figures):
    parts = []
    if not figures:
        parts.append(Markup('<p class="muted">No figures in this results directory.</p>'))
    for count, (name, mime, data, caption) in enumerate(figures, start=1):
        parts.append(html('<figure id="figure-{}"><img src="data:{};base64,{}" alt="{}">'
                          "<figcaption><strong>Figure {}.</strong> {} "
                          '<span class="muted">({})</span></figcaption></figure>', count, mime,
                          base64.b64encode(data).decode("ascii"), name, count, caption, name))
    return html('<section id="figures"><h2>Figures</h2>{}</section>', join(parts))


def inputs_section(results):
    inputs = results.get("inputs")
    not_set = {}
    blocks = []
    if isinstance(inputs, dict):
        inputs = dict(inputs)
        if isinstance(inputs.get("not_set"), dict):
            not_set = inputs.pop("not_set")
        simple = {k: v for k, v in inputs.items() if not isinstance(v, dict)}
        if simple:
            blocks.append(("case", "", simple))
        # [report] is the header's, not an input of the computation.
        blocks += [(k, k, client_inputs(results, k, v, not_set)) for k, v in inputs.items()
                   if isinstance(v, dict) and v and k != "report"]
    elif results.get("case") is not None:
        blocks.append(("case", "", {"name": results["case"]}))
    for key in ("truth", "expected", "measured", "record", "crowd_used", "msd", "levels"):
        if isinstance(results.get(key), dict) and not (key == "expected" and isinstance(
                inputs, dict) and inputs.get("expected") == results[key]):
            blocks.append((key, None, results[key]))
    for key in ("duration", "sample_rate", "elapsed_s"):
        if key in results:
            blocks.append((key, None, {key: results[key]}))
    cards = join(html('<div class="card"><h3>{}</h3>{}</div>', _capital(label(title)),
                      _input_rows(block, prefix, not_set)) for title, prefix, block in blocks)
    if not blocks:
        cards = Markup('<p class="muted">No inputs recorded in these results.</p>')
    note = (html('<p class="muted">Values marked <span class="default">default</span> were not '
                 'set in the case file; <span class="default">derived</span> ones were computed '
                 'from other inputs.</p>') if not_set else Markup(""))
    return html('<section id="inputs"><h2>Inputs</h2>{}<div class="cards">{}</div></section>',
                note, cards)


def _capital(text):
    """First letter upper case, the rest as written ("HSI (MSD model)", not "Msd Model")."""
    return text[:1].upper() + text[1:]


def _input_rows(block, prefix, not_set):
    """One card's rows; a key the case file left out is marked as a default (or derived)."""
    rows = []
    for key, data in block.items():
        how = None
        if prefix is not None:
            dotted = f"{prefix}.{key}" if prefix else key
            how = not_set.get(dotted, not_set.get(prefix) if prefix else None)
        cell = value(data, 1)
        if how == "default":
            cell = html('{} <span class="default">default</span>', cell)
        elif how:
            cell = html('{} <span class="default">derived {}</span>', cell, how)
        rows.append(html("<tr><th>{}</th><td>{}</td></tr>", label(key), cell))
    return html('<table class="kv">{}</table>', join(rows))


def _now():
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def provenance_section(results, directory):
    rows = [["command", results.get("command", "—")],
            ["crowdvib version of the run", results.get("crowdvib_version", "—")],
            ["crowdvib version of this report", __version__]]
    versions = results.get("versions")
    if isinstance(versions, dict):
        rows.append(["versions", ", ".join(f"{k} {v}" for k, v in versions.items())])
    case = results.get("case")
    # The case file as seen from the results folder, not the machine's path (issue 27 §4).
    base = None if directory is None else Path(directory).resolve()
    rows.append(["case", relative_path(case, base) if case is not None else "—"])
    digest, how = results.get("case_sha256"), "recorded by the run"
    if digest is None and case is not None:
        # Only a case file beside the results is hashed: a results file cannot make the report
        # read an arbitrary path (issue 9).
        path = Path(str(case))
        if directory is not None and not path.is_absolute():
            path = directory / path
        if path.suffix == ".toml" and path.is_file():
            digest, how = sha256_file(path), "of the file as it is now, when the report was written"
        else:
            how = "no case file (embedded example or file not found)"
    rows.append(["case file SHA-256", html("{}<span class=\"muted\">({})</span>",
                                           html("<code>{}</code> ", digest) if digest else "—",
                                           how)])
    rows.append(["seed", number(results.get("seed"))])
    created = results.get("created") or results.get("date")
    if created is None and directory is not None and (directory / "results.json").is_file():
        stamp = (directory / "results.json").stat().st_mtime
        created = (datetime.datetime.fromtimestamp(stamp, datetime.timezone.utc)
                   .isoformat(timespec="seconds") + " (time of results.json)")
    rows.append(["run date", created or "—"])
    if directory is not None and (directory / "results.json").is_file():
        rows.append(["results.json SHA-256",
                     html("<code>{}</code>", sha256_file(directory / "results.json"))])
    rows.append(["report written", _now()])
    return html('<section id="provenance"><h2>Provenance</h2>{}</section>',
                table(["", ""], rows, "data narrow provenance"))
