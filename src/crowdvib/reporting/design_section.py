"""The design checks of ``crowdvib check`` in report.html: one decision per code, the tuned mass
damper crowdvib designed (or was given), the MSD model the checks used, and the verdict table
(issue 27 §4: the numbers a client pays for are in the report, not only in results.json), with
the UK NA's γ figure and crowd cap, both readings of n_eq's damping and the codes' defaults not
verified against their guide (issue 33).

Each function returns empty Markup (or None) for the results of other commands.
"""

from markupsafe import Markup

from ..cases.schema import get, real
from ..design.registry import code_label
from .design_plots import MODEL_LABELS
from .html import html, join, number, table

__all__ = ["design_decisions", "damper_items", "msd_section", "design_section", "design_inputs"]

#: Codes that define comfort classes CL1–CL4 (:func:`crowdvib.design.codes.comfort_limit`).
_COMFORT_CODES = ("setra", "hivoss")


#: The design card's line of the defaults no public text confirmed (issue 33 §2).
UNVERIFIED_LABEL = "defaults not verified against the guide"


def _checks(results):
    """Code → its check in results.json (``design.checks``), dicts only."""
    checks = get(results, ("design", "checks"))
    return {k: c for k, c in checks.items() if isinstance(c, dict)} \
        if isinstance(checks, dict) else {}


def design_inputs(results, block):
    """The ``[design]`` input card's rows: the case file's, and the checked codes' defaults not
    verified against their guide, code by code ("UK NA: …; Sétra: …") from each check's
    ``details["unverified_defaults"]`` (:data:`crowdvib.design.codes.UNVERIFIED_DEFAULTS`)."""
    parts = []
    for code, check in _checks(results).items():
        listed = get(check, ("details", "unverified_defaults"))
        if isinstance(listed, list) and listed:
            parts.append(f"{code_label(code)}: {'; '.join(map(str, listed))}")
    return {**block, UNVERIFIED_LABEL: ". ".join(parts)} if parts else block


def _rows(results):
    rows = get(results, ("design", "verdict"))
    return [r for r in rows if isinstance(r, dict)] if isinstance(rows, list) else []


def _code(row):
    code = code_label(row.get("code"))
    return f"{code} {row['traffic_class']}" if row.get("traffic_class") else code


def design_decisions(results):
    """One sentence per code: passes or fails with the primary model (HSI when checked, else no
    HSI: the verdict's rule, :mod:`crowdvib.cases.verdict`), at its largest utilisation."""
    rows = _rows(results)
    primary = "HSI" if any(r.get("model") == "HSI" for r in rows) else "no HSI"
    decisions = []
    for code in dict.fromkeys(r.get("code") for r in rows):
        mine = [r for r in rows if r.get("code") == code and r.get("model") == primary
                and real(r.get("utilisation")) is not None]
        if not mine:
            continue
        worst = max(mine, key=lambda r: r["utilisation"])
        failing = [r for r in mine if r.get("passes") is False]
        if failing:
            decisions.append(html('{}: <strong>fails</strong> with {} at {} (utilisation {})',
                                  _code(worst), primary,
                                  ", ".join(str(r.get("output")) for r in failing),
                                  number(worst["utilisation"], 3)))
        else:
            decisions.append(html("{}: passes with {} (largest utilisation {}, at {})",
                                  _code(worst), primary, number(worst["utilisation"], 3),
                                  worst.get("output")))
    return decisions


def _dampers(results):
    dampers = get(results, ("design", "dampers"))
    return [d for d in dampers if isinstance(d, dict)] if isinstance(dampers, list) else []


def damper_items(results):
    """A headline per tuned mass damper: mass, frequency, damping ratio and position."""
    return [html("tuned mass damper{}: {} kg, {} Hz, damping ratio {}, at {} m",
                 f" {k}" if len(_dampers(results)) > 1 else "", number(d.get("mass"), 4),
                 number(d.get("frequency"), 4), number(d.get("damping_ratio"), 3),
                 number(d.get("position"), 4))
            for k, d in enumerate(_dampers(results), start=1)]


def _damper_table(results):
    dampers = _dampers(results)
    if not dampers:
        return Markup("")
    spec = get(results, ("inputs", "design", "damper"))
    how = (html("designed by crowdvib for mode {} with {} of its modal mass: placed at the "
                "mode's antinode, frequency and damping ratio tuned to the occupied mode "
                "(docs: theory, Tuning a TMD)", spec["mode"], _percent(spec.get("mass_ratio")))
           if isinstance(spec, dict) and "mode" in spec else Markup("as stated in the case file"))
    rows = [[f"damper {k}", number(d.get("mass"), 4), number(d.get("frequency"), 4),
             number(d.get("damping_ratio"), 3), number(d.get("position"), 4),
             number(d.get("lane")) if d.get("lane") is not None else "—"]
            for k, d in enumerate(dampers, start=1)]
    return html("<h3>Tuned mass damper</h3><p>The checks include the damper below, {}.</p>{}",
                how, table(["", "mass [kg]", "frequency [Hz]", "damping ratio [-]",
                            "position along the walkway [m]", "lane"], rows, "data"))


def _percent(fraction):
    return html("{} %", number(100 * fraction, 3)) if real(fraction) is not None else "—"


def msd_section(results):
    """The MSD pedestrian model the checks' HSI rows used (in place of an estimate), or None for
    other commands."""
    if results.get("command") != "check":
        return None
    msd = results.get("msd")
    if not isinstance(msd, dict):
        body = Markup('<p class="muted">The checks use no MSD model: no HSI rows.</p>')
    else:
        rows = [[Markup("f<sub>h1</sub> [Hz]"), number(msd.get("frequency"))],
                [Markup("ξ<sub>h1</sub> [-]"), number(msd.get("damping_ratio"))],
                [Markup("μ<sub>h1</sub> [-]"), number(msd.get("mass_ratio"))]]
        body = html("<p>The HSI rows of the checks model each pedestrian by this MSD (from "
                    "{}).</p>{}{}", msd.get("source") or "the case file",
                    table(["parameter", "value"], rows, "data narrow"), _over_interval(results))
    return html('<section id="estimate"><h2>MSD model used</h2>{}</section>', body)


def _over_interval(results):
    """Identification → uncertainty → design in one table (issue 27 §3): each code's utilisation
    at the estimate and over the box of f_h1 and ξ_h1 the estimate allows, with the verdict at
    the conservative end (``hsi_range``, :func:`crowdvib.cases.design.check_over_interval`)."""
    ranges = results.get("hsi_range")
    if not isinstance(ranges, dict) or not ranges:
        return Markup("")
    first = next(iter(ranges.values()))
    box = html("f<sub>h1</sub> {}–{} Hz, ξ<sub>h1</sub> {}–{}",
               *(number(v, 4) for name in ("frequency", "damping_ratio")
                 for v in (first.get(name) or [None, None])))
    rows = []
    for code, row in ranges.items():
        end = row.get("conservative_end") or {}
        rows.append([code_label(code), number(row.get("utilisation"), 3),
                     html("{}–{}", number(row.get("low"), 3), number(row.get("high"), 3)),
                     html("{} Hz, {}", number(end.get("frequency"), 4),
                          number(end.get("damping_ratio"), 3)),
                     row.get("verdict") or "—"])
    return html("<h3>Over the estimate's uncertainty</h3><p>The checks repeated across the box "
                "{} ({}; μ<sub>h1</sub> held), which is wider than the joint confidence region: "
                "the verdict is the one at the conservative end, where the utilisation is "
                "highest.</p>{}", box, first.get("interval") or "interval",
                table(["code", "utilisation at the estimate", "over the box",
                       "conservative end (f_h1, ξ_h1)", "verdict"], rows, "data"))


def _ukna_notes(results):
    """What the UK NA check read its γ from, the crowd's load density where the NA capped it
    (NA.2.44.5(1)) and what γ read at the edge of its figure's grid."""
    notes = []
    for check in _checks(results).values():
        details = check.get("details") if isinstance(check.get("details"), dict) else {}
        if "gamma_figure" not in details:
            continue
        notes.append(html("UK NA: γ of the walkers and joggers from {} (gamma_figure = "
                          '"{}").', details.get("gamma_figure_label") or "—",
                          details.get("gamma_figure")))
        crowd = get(details, ("cases", "crowd")) or {}
        if real(crowd.get("load_density")) is not None and real(crowd.get("density")) is not None \
                and crowd["load_density"] < crowd["density"]:
            notes.append(html("UK NA crowd: the load takes ρ = {} persons/m², the class's {} "
                              "capped as NA.2.44.5(1) requires; the added-mass and HSI models "
                              "carry the {} persons/m².", number(crowd["load_density"], 3),
                              number(crowd["density"], 3), number(crowd["density"], 3)))
        for note in details.get("gamma_outside_grid") or []:
            notes.append(html("UK NA γ outside its figure: {}.", note))
    return join(html("<p>{}</p>", note) for note in notes)


def _neq_readings(results):
    """The Sétra/HiVoSS/EN 1990 checks with HSI under both readings of n_eq's damping, side by
    side (docs: theory, The equivalent crowd with HSI): the governing acceleration and the
    utilisation with the occupied and with the empty structure's ξ."""
    rows = []
    for code, check in _checks(results).items():
        readings = get(check, ("details", "equivalent_pedestrians"))
        models, names = check.get("models") or [], check.get("output_names") or []
        if not isinstance(readings, dict) or "hsi" not in models or not real(check.get("limit")):
            continue
        model = models.index("hsi")
        used = readings.get("damping")
        label = _code({"code": code, "traffic_class": check.get("traffic_class")})
        for output, name in enumerate(names):
            peaks = [get(readings, ("governing", reading)) for reading in ("occupied", "empty")]
            peaks = [p[model][output] if isinstance(p, list) else None for p in peaks]
            rows.append([label, name, *(cell for peak in peaks for cell in (
                number(peak, 3), number(peak / check["limit"], 3) if real(peak) is not None
                else "—")), used or "—"])
    if not rows:
        return Markup("")
    return html("<h3>Equivalent crowd with HSI: the damping of n<sub>eq</sub></h3><p>n<sub>eq</sub>"
                " = 10.8 √(ξ n) read with the occupied mode's ξ and with the empty structure's "
                "ξ (neq_damping; docs: theory, The equivalent crowd with HSI). The HSI rows "
                "above use the reading in the last column; the no-HSI and added-mass rows are "
                "the same under both.</p>{}",
                table(["code and class", "output", "a, occupied ξ [m/s²]",
                       "utilisation, occupied ξ", "a, empty ξ [m/s²]", "utilisation, empty ξ",
                       "verdict uses"], rows, "data"))


def design_section(results: dict) -> Markup:
    """The damper, the verdict table and the crowd stream's prediction of ``crowdvib check``;
    empty for other commands.

    A check that fails with the primary model (HSI when checked, else no HSI) fails the verdict
    (:mod:`crowdvib.cases.verdict`).
    """
    rows = _rows(results)
    if not rows:
        return Markup("")
    cells = [[_code(r), r.get("model"), r.get("output"),
              number(r.get("governing"), 3), number(r.get("limit"), 3),
              number(r.get("utilisation"), 3),
              (r.get("comfort_class") or "—") if r.get("code") in _COMFORT_CODES else "—",
              "yes" if r.get("passes") else "no"] for r in rows]
    prediction = get(results, ("design", "prediction"))
    extra = ""
    if isinstance(prediction, dict) and isinstance(prediction.get("rms"), list):
        names = prediction.get("output_names") or []
        lines = [[MODEL_LABELS.get(model, model), name, number(rms, 3), number(peak, 3)]
                 for model, rms_row, peak_row in zip(prediction.get("models") or [],
                                                     prediction["rms"],
                                                     prediction.get("expected_peak") or [])
                 for name, rms, peak in zip(names, rms_row, peak_row)]
        extra = html("<h3>Crowd stream ({} persons/m², record {} s)</h3>{}",
                     number(prediction.get("density"), 3), number(prediction.get("duration")),
                     table(["model", "output", "RMS [m/s²]", "expected peak [m/s²]"], lines,
                           "data"))
    note = Markup('<p class="muted">Comfort classes CL1–CL4 are defined by Sétra and HiVoSS '
                  "only; EN 1990 and the UK NA set a limit alone.</p>")
    return html('<section id="design"><h2>Design checks</h2>{}{}{}{}{}{}</section>',
                _damper_table(results),
                table(["code and class", "model", "output", "a [m/s²]", "limit [m/s²]",
                       "utilisation", "comfort class", "passes"], cells, "data"), note,
                _ukna_notes(results), _neq_readings(results), extra)
