"""The report of ``crowdvib season``: the document a client reads of a monitoring season (issue 36
§1).

The season's report is the estimate report's page with the season in it: its span under the
title (dates, rows, records, hours, densities), the joint estimate with the rows it rests on,
a Records section with every row of the crowd table (its crowd, f_h1 and ξ_h1 with their
intervals, its status, whether the joint estimate holds it and why not), the records' warnings
counted in the summary, diagnostics of the joint fit (its outputs, not one per record), and
Inputs that describe what the season used: the crowd table and its records, not the case file's
own record and crowd density. :func:`season_body` replaces those blocks of the page.
"""

from markupsafe import Markup

from .._estimators import METHOD_WORDS
from ..cases.schema import estimate, get
from . import sections
from .html import html, join, number, table
from .text import interval_of, with_interval

__all__ = ["season_body", "season_span", "why_not_joint"]

_PARAMETERS = (("frequency", Markup("f<sub>h1</sub>"), "Hz"),
               ("damping_ratio", Markup("ξ<sub>h1</sub>"), "-"))
#: The joint estimate's interval methods by name.
_INTERVAL_NAMES = {"wald": "Wald interval", "profile": "profile interval",
                   "bootstrap": "bootstrap interval", None: "no interval"}
#: Rows of the "rests on" sentence; the Records table marks every one.
_NAMED = 30


def season_body(shown, notes, body):
    """The page's blocks (:data:`crowdvib.reporting.template.BLOCKS` order) with the season's
    header, summary, estimate (the joint estimate and the Records section), diagnostics and
    inputs; the figures and provenance as they are.

    Parameters
    ----------
    shown : dict
        The season's results.json, without the machine's paths.
    notes : Notes
        The verdict's findings and the run's warnings.
    body : list of Markup
        The blocks of the estimate report's page.
    """
    header, _, _, _, _, figures, _, provenance = body
    described = dict(shown.get("inputs") or {}) if isinstance(shown.get("inputs"), dict) else {}
    described["description"] = season_span(shown)
    header = sections.header({**shown, "inputs": described})
    return [header, sections.nav(shown), _summary(shown, notes),
            join([_estimate(shown), _records(shown)]), _diagnostics(shown), figures,
            _inputs(shown), provenance]


def _rows(results):
    rows = results.get("records")
    return [row for row in rows if isinstance(row, dict)] if isinstance(rows, list) else []


def season_span(results):
    """The season in one sentence: its rows and records, from when to when, how many hours
    were estimated, its densities (plain text)."""
    rows = _rows(results)
    table_name = str(results.get("crowd_table") or "the crowd table").replace("\\", "/")
    records = len({row.get("record") for row in rows})
    parts = [f"A season of {len(rows)} row(s) of {table_name.rsplit('/', 1)[-1]} on "
             f"{records} record(s)"]
    times = sorted(str(row["time"]) for row in rows if row.get("time"))
    if times:
        first, last = _time(times[0]), _time(times[-1])
        if last[:10] == first[:10]:
            last = last[11:]
        parts.append(f"{first} to {last}" if last != first else first)
    seconds = [row["duration"] for row in rows
               if isinstance(row.get("duration"), (int, float)) and row.get("status") in
               ("ok", "doubt")]
    if seconds:
        parts.append(f"{sum(seconds) / 3600:.3g} h of records estimated")
    densities = [row["density"] for row in rows if isinstance(row.get("density"), (int, float))]
    if densities:
        parts.append(f"densities {min(densities):.3g}–{max(densities):.3g} persons/m²")
    return ", ".join(parts)


def _time(text):
    """An ISO 8601 time as a reader reads it: the date and the hour."""
    return str(text).replace("T", " ")[:16]


# ------------------------------------------------------------------------------ summary
def _summary(shown, notes):
    found, rows = estimate(shown), _rows(shown)
    items = []
    if found:
        for key, symbol, unit in _PARAMETERS:
            if isinstance(found.get(key), (int, float)):
                items.append(html("{} = {} (joint estimate)", symbol, with_interval(
                    found[key], interval_of(found, key), unit)))
        items.append(_rests_on(rows))
        relative = get(shown, ("diagnostics", "relative_cost"))
        if isinstance(relative, (int, float)):
            items.append(html("J/J<sub>noHSI</sub> = {} (joint fit)", number(relative, 3)))
    else:
        items.append(html("no joint estimate: {}", _no_joint(shown)))
    states = [row.get("status") for row in rows]
    items.append(html("{} row(s): {}", len(rows), ", ".join(
        f"{states.count(s)} {s}" for s in ("ok", "doubt", "error", "skipped") if s in states)))
    return html('<section id="summary"><h2>Summary</h2><ul class="headline">{}</ul>{}'
                "</section>", join(html("<li>{}</li>", i) for i in items),
                sections.verdict_box(notes, _doubtful(rows)))


def _rests_on(rows, named=False):
    """What the joint estimate rests on: how many rows, and with ``named`` which."""
    used = [row for row in rows if row.get("in_joint")]
    if not named:
        return html("the joint estimate rests on {} of the {} row(s) (named under Records)",
                    len(used), len(rows))
    names = ", ".join(f"row {row.get('row', '?')} {row.get('name')}" for row in used[:_NAMED])
    more = f" and {len(used) - _NAMED} more" if len(used) > _NAMED else ""
    return html("The joint estimate rests on {} of the {} row(s): {}{}.", len(used), len(rows),
                names, more)


def _doubtful(rows):
    """The rows in doubt or failed, each with its warnings, counted (the box's last part)."""
    chosen = [row for row in rows if row.get("status") in ("doubt", "error")]
    if not chosen:
        return Markup("")
    return html("<p>The records' own warnings ({} row(s)):</p><ul>{}</ul>", len(chosen),
                join(html("<li>row {} {} ({}): {}</li>", row.get("row", "?"), row.get("name"),
                          row.get("status"), sections.finding_markup(str(row.get("warnings"))))
                     for row in chosen))


def _no_joint(results):
    if results.get("joint_error"):
        return f"it failed ({results['joint_error']}); the records' own estimates stand"
    if not any(row.get("status") in ("ok", "doubt") for row in _rows(results)):
        return "no row was estimated"
    return "not asked for (--no-joint)"


# ------------------------------------------------------------------------------ estimate
def _estimate(shown):
    if estimate(shown):
        return Markup(sections.estimate_section(shown).replace(
            "<h2>Estimate</h2>", Markup("<h2>Joint estimate</h2>"), 1))
    return html('<section id="estimate"><h2>Joint estimate</h2><p>No joint estimate: {}.</p>'
                "</section>", _no_joint(shown))


def why_not_joint(row, results):
    """Whether the joint estimate holds a row, and why not (plain text).

    Parameters
    ----------
    row : dict
        A row of the season's table.
    results : dict
        The season's results.json (``estimate``, ``joint_error``, ``joint_min_density``).
    """
    if row.get("in_joint"):
        return "yes"
    status = row.get("status")
    if status == "skipped":
        return f"no: not estimated ({row.get('warnings')})"
    if status == "error":
        return "no: its estimate failed"
    if results.get("joint_error"):
        return "no: the joint estimate failed"
    if not estimate(results):
        return "no: no joint estimate (--no-joint)"
    least = results.get("joint_min_density")
    if isinstance(least, (int, float)) and isinstance(row.get("density"), (int, float)) \
            and row["density"] < least:
        return f"no: density below {least:g} persons/m² (--joint-min-density)"
    return "no"


def _records(shown):
    rows = _rows(shown)
    level = next((row["level"] for row in rows if isinstance(row.get("level"), (int, float))),
                 0.95)
    cells = []
    for row in rows:
        status = row.get("status") or "—"
        if status in ("doubt", "error"):
            status = html('<span class="badge warn">{}</span>', status)
        cells.append([number(row.get("row")), row.get("name") or "—",
                      _time(row["time"]) if row.get("time") else "—",
                      number(row.get("duration"), 4), number(row.get("count"), 4),
                      number(row.get("density"), 3), _with_ends(row, "frequency"),
                      _with_ends(row, "damping_ratio"), status, why_not_joint(row, shown)])
    parts = [html("<p>{}</p><p>Every row of the crowd table, estimated on its own with its {} % "
                  "interval by the case's estimator; the last column says whether the joint "
                  "estimate holds it, and why not.</p>",
                  _rests_on(rows, named=True) if estimate(shown)
                  else html("No joint estimate: {}.", _no_joint(shown)), number(100 * level)),
             table(["row", "record or window", "time", "length [s]", "count [persons]",
                    "density [persons/m²]", Markup("f<sub>h1</sub> [Hz]"),
                    Markup("ξ<sub>h1</sub> [-]"), "status", "in the joint estimate"],
                   cells, "data")]
    unmatched = shown.get("unmatched_records")
    if isinstance(unmatched, list) and unmatched:
        parts.append(html("<p>Records found that no row of the crowd table names (not "
                          "estimated): {}.</p>", ", ".join(map(str, unmatched))))
    return html('<section id="records"><h2>Records</h2>{}</section>', join(parts))


def _with_ends(row, key):
    """A row's estimate with its interval, "3.2 (2.85–3.68)", or —."""
    if not isinstance(row.get(key), (int, float)):
        return Markup("—")
    low, high = row.get(f"{key}_low"), row.get(f"{key}_high")
    if isinstance(low, (int, float)) and isinstance(high, (int, float)):
        return html("{} ({}–{})", number(row[key], 3), number(low, 3), number(high, 3))
    return number(row[key], 3)


# ------------------------------------------------------------------------------ the rest
def _diagnostics(shown):
    """The joint fit's diagnostics: its outputs once (not "record 1: …" per record), and every
    warning of the run, the records' own among them (each named by its row)."""
    diagnostics = dict(shown.get("diagnostics") or {}) \
        if isinstance(shown.get("diagnostics"), dict) else {}
    names = diagnostics.pop("output_names", None)
    diagnostics.pop("output_weights", None)       # one per record and output: all alike
    if isinstance(names, list):
        diagnostics["output_names"] = list(dict.fromkeys(
            str(name).split(": ", 1)[-1] for name in names))
    own = [f"row {row.get('row', '?')} {row.get('name')}: {row.get('warnings')}"
           for row in _rows(shown) if row.get("status") in ("doubt", "error")]
    warned = [*(shown.get("warnings") if isinstance(shown.get("warnings"), list) else []), *own]
    return sections.diagnostics_section({**shown, "diagnostics": diagnostics or None,
                                         "warnings": warned})


def _joint_words(results):
    """The joint fit's estimator and interval, in words."""
    method = get(results, ("diagnostics", "method"))
    ends = (estimate(results) or {}).get("interval")
    how = ends.get("method") if isinstance(ends, dict) else None
    if method is None:
        return "none"
    return (f"the case's estimator ({METHOD_WORDS.get(method, method)}) over the rows it "
            f"holds, each with its crowd; " + _INTERVAL_NAMES.get(how, f"{how} interval"))


def _inputs(shown):
    """The case's tables as the season used them (the records and their crowds are the crowd
    table's: not the case file's own record, density and what derives from it), and the
    season's own card."""
    inputs = dict(shown.get("inputs") or {}) if isinstance(shown.get("inputs"), dict) else {}
    not_set = inputs.get("not_set") if isinstance(inputs.get("not_set"), dict) else {}
    if isinstance(inputs.get("measurement"), dict):
        inputs["measurement"] = {k: v for k, v in inputs["measurement"].items() if k != "files"}
    if isinstance(inputs.get("crowd"), dict):
        # What the case derives from its density is derived from each row's (cases.season).
        per_row = {"density"} | {key for key in ("walking_speed", "step_frequency_mean")
                                 if f"crowd.{key}" in not_set}
        inputs["crowd"] = {k: v for k, v in inputs["crowd"].items() if k not in per_row}
    rows = _rows(shown)
    table_name = str(shown.get("crowd_table") or "—").replace("\\", "/").rsplit("/", 1)[-1]
    inputs["season"] = {
        "crowd table": table_name, "rows of the crowd table [-]": len(rows),
        "records estimated [-]": len({row.get("record") for row in rows
                                       if row.get("status") in ("ok", "doubt")}),
        "crowd of each row": "the crowd table's count or density (and step frequencies); "
                             "the case's crowd gives the rest",
        "joint estimate": _joint_words(shown),
        "least density of a row in the joint estimate [persons/m²]":
            shown.get("joint_min_density", 0.0)}
    return sections.inputs_section({**shown, "inputs": inputs})
