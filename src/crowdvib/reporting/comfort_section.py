"""A year of comfort (``crowdvib comfort``) in report.html: hours a year per comfort class and
the probability that a 10-minute window exceeds each limit, per model and damper, with the band
of the HSI's interval and of the season's sampling; where the traffic and the MSD come from,
and where the spectral route is not to be trusted (issue 37).

Each function returns empty Markup for the results of other commands.
"""

from markupsafe import Markup

from ..cases.schema import get, real
from .html import html, join, number, table

__all__ = ["comfort_section", "comfort_headline"]


def _year(results):
    year = results.get("comfort")
    return year if isinstance(year, dict) and isinstance(year.get("rows"), list) else None


def _label(row):
    return f"{row.get('label')}{' + damper' if row.get('damper') else ''}"


def _with_band(value, band, digits):
    """A value and its band ``low–high`` (or the value alone)."""
    if not (isinstance(band, list) and len(band) == 2 and all(real(v) is not None
                                                              for v in band)):
        return number(value, digits)
    return html("{} ({}–{})", number(value, digits), number(band[0], digits),
                number(band[1], digits))


def _band(row, key, name):
    for which in ("hsi", "sampling"):
        found = get(row, (f"{key}_band_{which}", name))
        if found is not None:
            return found
    return None


def comfort_section(results: dict) -> Markup:
    """The year's tables and notes; empty for other commands."""
    year = _year(results)
    if year is None:
        return Markup("")
    settings = year.get("settings") or {}
    classes = [c for c in settings.get("classes") or [] if isinstance(c, list) and c]
    names = [str(c[0]) for c in classes]
    rows = [r for r in year["rows"] if isinstance(r, dict)]
    hours = [[_label(r), *(_with_band(get(r, ("hours_per_class", n)), _band(r, "hours", n), 4)
                           for n in names),
              number(sum(v for v in (r.get("hours_per_class") or {}).values()
                         if real(v) is not None), 5)] for r in rows]
    limits = [f"{v:g}" for v in settings.get("limits") or [] if real(v) is not None]
    exceed = [[_label(r), *(_with_band(get(r, ("exceedance", k)), _band(r, "exceedance", k), 3)
                            for k in limits)] for r in rows]
    bounds = join([html("{} ≤ {} m/s²", c[0], number(c[1])) if real(c[1]) is not None
                   else html("{} above", c[0]) for c in classes], Markup(", "))
    return html(
        '<section id="comfort"><h2>A year of comfort</h2>{}'
        "<h3>Hours a year per comfort class</h3>{}<p class=\"muted\">Sétra/HiVoSS classes of "
        "the {}-s peak acceleration at {}: {}. In brackets the band: the identified HSI over "
        "the corners of its interval (HSI rows), or the central 95 % of the season's windows "
        "drawn again (other rows of a season).</p>"
        "<h3>Probability that a window exceeds a limit</h3>{}{}</section>",
        _notes(results, settings),
        table(["model", *(f"{n} [h]" for n in names), "sum [h]"], hours, "data"),
        number(settings.get("duration")), settings.get("output"), bounds,
        table(["model", *(f"> {k} m/s²" for k in limits)], exceed, "data"),
        _validity(settings))


def _notes(results, settings):
    """Where the traffic, the MSD and its box come from, and how the peak is modelled."""
    box = results.get("msd_interval") if isinstance(results.get("msd_interval"), dict) else None
    msd = results.get("msd") if isinstance(results.get("msd"), dict) else {}
    filled = settings.get("filled_hours") or []
    items = [html("<li>Traffic: {} ({} h a year{}).</li>", results.get("traffic_from"),
                  number(settings.get("total_hours"), 5),
                  html(", {} of the 168 hours of the week measured, the others filled by the "
                       "rule “{}”", 168 - len(filled), settings.get("unmeasured"))
                  if settings.get("traffic_source") == "season" and
                  settings.get("week_hours") else "")]
    if msd:
        items.append(html("<li>MSD of the identified HSI: f<sub>h1</sub> = {} Hz, ξ<sub>h1</sub>"
                          " = {}, μ<sub>h1</sub> = {} ({}){}.</li>", number(msd.get("frequency")),
                          number(msd.get("damping_ratio")), number(msd.get("mass_ratio")),
                          results.get("msd_source"),
                          html("; band over {} f<sub>h1</sub> {}–{} Hz, ξ<sub>h1</sub> {}–{}",
                               box.get("interval"), *(number(v) for v in
                                                      (box.get("frequency") or [None] * 2)),
                               *(number(v) for v in (box.get("damping_ratio") or [None] * 2)))
                          if box else ""))
    dampers = settings.get("dampers") or []
    if dampers:
        first = dampers[0]
        items.append(html("<li>Damper of the “+ damper” rows: {} kg at {} Hz, ξ = {}, at x = {} m"
                          ".</li>", number(first.get("mass")), number(first.get("frequency")),
                          number(first.get("damping_ratio")), number(first.get("position"))))
    items.append(html("<li>Peak of a window: {} law from the response's spectral moments "
                      "(docs: theory, A year of comfort); {} of the expected PSD.</li>",
                      settings.get("peak_model"), settings.get("crowd_model")))
    return html("<ul>{}</ul>", join(items))


def _validity(settings):
    return html('<p class="muted">The spectral route takes the response of each crowd state '
                "as stationary and Gaussian. For a thin crowd it is not: on the paper's bridge "
                "the 99 % quantile of the simulator's 10-minute peaks runs 6–14 % above the "
                "spectral one at 0.1–0.5 persons/m², fewer than 100 walkers on the walkway "
                "(on a bridge whose mode moves part of the walkway, more). "
                "Below that crowd the simulator stands in by default ([comfort] simulate_below; "
                "0 switches it off; accuracy/comfort_validation.py; docs: theory, A year of "
                "comfort).{}{}</p>", _simulated_note(settings), _thin_note(settings))


def _simulated_note(settings):
    below = real(settings.get("simulate_below"))
    if not below:
        return ""
    return html(" Here the simulator's windows stand in below {} persons/m² for the rows "
                "{}.", number(below), ", ".join(f"{m}{' + damper' if d else ''}"
                                                for m, d in settings.get("simulated_rows") or []))


def _thin_note(settings):
    hours = real(settings.get("spectral_thin_hours"))
    if not hours:
        return ""
    return html(" {} hours a year of this traffic lie below the thin crowd's {} persons/m² "
                "and are judged by the spectral route all the same: its upper quantiles read "
                "low there.", number(hours), number(settings.get("thin_crowd_density")))


def comfort_headline(results: dict) -> list:
    """The summary's lines of a year of comfort: per model without and with the damper, the
    hours a year above CL1 (the primary model, identified HSI when present, first)."""
    year = _year(results)
    if year is None:
        return []
    rows = [r for r in year["rows"] if isinstance(r, dict)]
    first = [r for r in rows if r.get("model") == "hsi"] or rows[:1]
    items = []
    for row in first + [r for r in rows if r not in first and r.get("model") == "empty"]:
        hours = row.get("hours_per_class") or {}
        above = sum(v for k, v in hours.items() if k != "CL1" and real(v) is not None)
        items.append(html("{}: {} h a year above CL1 (0.5 m/s²), {} h in CL3 or CL4",
                          _label(row), number(above, 4),
                          number(sum(v for k, v in hours.items() if k in ("CL3", "CL4")
                                     and real(v) is not None), 4)))
    return items
