"""The identified modes of ``crowdvib modes`` in report.html, with the second method's cross-check.

A mode the two methods do not agree on (a difference beyond ``level`` combined standard
deviations, or not found by the second method) is a doubt: the verdict names it
(:mod:`crowdvib.cases.verdict`).
"""

from markupsafe import Markup

from ..cases.verdict import method_name as _name
from .html import html, join, number, table

__all__ = ["modes_section", "modes_headline"]


def modes_headline(results: dict) -> list:
    """The summary's line of a ``modes`` result: how many modes, by which method, at which
    frequencies (in place of an estimate's); empty for other commands."""
    modes = results.get("modes")
    if results.get("command") != "modes" or not isinstance(modes, list):
        return []
    frequencies = [number(m.get("frequency"), 4) for m in modes if isinstance(m, dict)]
    return [html("{} modes identified by {}: {} Hz", len(modes),
                 _name(results.get("method", "ssi-cov")), join(frequencies, ", ") or "—")]


def modes_section(results: dict) -> Markup:
    """Modes table, cross-check table and per-setup table of a ``modes`` results file; empty for
    other commands."""
    modes = results.get("modes")
    if results.get("command") != "modes" or not isinstance(modes, list):
        return Markup("")
    modes = [m if isinstance(m, dict) else {} for m in modes]
    method = _name(results.get("method", "ssi-cov"))
    rows = [[f"mode {j + 1}", number(m.get("frequency"), 5), number(m.get("frequency_std"), 2),
             number(m.get("damping_ratio"), 4), number(m.get("damping_std"), 2)]
            for j, m in enumerate(modes)]
    parts = [html("<p>{} modes identified by {}; standard deviations σ.</p>", len(modes), method),
             table(["mode", "f [Hz]", "σ_f [Hz]", "ξ [-]", "σ_ξ [-]"], rows, "data"),
             _shapes(modes, results.get("sensor_names"))]
    missed = results.get("missed")
    if isinstance(missed, list) and missed:
        parts.append(_missed(missed, len(modes)))
    check = results.get("cross_check")
    if isinstance(check, dict) and isinstance(check.get("modes"), list):
        parts.append(_cross_check(check, modes, method))
    setups = results.get("setups")
    if isinstance(setups, list) and setups:
        parts.append(_setups(setups, len(modes)))
    return html('<section id="modes"><h2>Identified modes</h2>{}</section>', join(parts))


def _shapes(modes, sensors):
    """Mode × sensor table of the real shapes, 1 at each mode's largest component."""
    shapes = [m.get("mode_shape") if isinstance(m.get("mode_shape"), list) else [] for m in modes]
    count = max(map(len, shapes), default=0)
    if not count:
        return Markup("")
    sensors = sensors if isinstance(sensors, list) and len(sensors) == count else [
        f"sensor {i + 1}" for i in range(count)]
    rows = [[f"mode {j + 1}", number(m.get("frequency"), 4)]
            + [number(shape[i], 3) if i < len(shape) else "—" for i in range(count)]
            for j, (m, shape) in enumerate(zip(modes, shapes))]
    return html("<h3>Mode shapes</h3><p>Real mode shapes at the sensors, each scaled to 1 at "
                "its largest component (OMA gives no modal masses, hence no absolute scale).</p>"
                "{}", table(["mode", "f [Hz]", *map(str, sensors)], rows, "data"))


def _missed(missed, n_modes):
    """Stable columns of the stabilisation diagram that are not among the modes reported."""
    rows = []
    for column in missed:
        column = column if isinstance(column, dict) else {}
        rows.append([number(column.get("frequency"), 4), number(column.get("damping_ratio"), 3),
                     html("{} of {}", column.get("orders", "—"), column.get("of_orders", "—"))]
                    + ([str(column["setup"])] if "setup" in column else []))
    setup = any(isinstance(c, dict) and "setup" in c for c in missed)
    return html('<div class="callout warn"><h3>Stable columns not reported</h3><p>The '
                "stabilisation diagram has {} column(s) of stable poles that pass the checks of a physical "
                "mode but are not among the {} mode(s) reported (dashed on the diagram). Raise "
                "<code>n_modes</code> to report them, or narrow <code>frequency_band</code> to "
                "leave them out.</p>{}</div>", len(missed), n_modes,
                table(["f [Hz]", "ξ [-]", "stable over model orders"]
                      + (["setup"] if setup else []), rows, "data"))


def _cross_check(check, modes, method):
    other = _name(check.get("method"))
    level = check.get("level", 1.96)
    rows = []
    for j, (mine, row) in enumerate(zip(modes, check["modes"])):
        row = row if isinstance(row, dict) else {}
        agree = row.get("agree") is True
        rows.append([f"mode {j + 1}", number(mine.get("frequency"), 5),
                     number(row.get("frequency"), 5), number(row.get("frequency_difference"), 2),
                     number(row.get("frequency_z"), 2), number(mine.get("damping_ratio"), 4),
                     number(row.get("damping_ratio"), 4),
                     number(row.get("damping_difference"), 2), number(row.get("damping_z"), 2),
                     number(row.get("mac"), 4), "yes" if agree else "no"])
    headers = ["mode", html("f {} [Hz]", method), html("f {} [Hz]", other), "Δf [Hz]", "z_f",
               html("ξ {}", method), html("ξ {}", other), "Δξ", "z_ξ", "MAC", "agree"]
    return html("<h3>Cross-check by {}</h3><p>Differences {} − {}, and in combined standard "
                "deviations z = Δ/√(σ₁² + σ₂²); agreement: |z| ≤ {} for f and ξ.</p>{}", other,
                other, method, number(level, 3), table(headers, rows, "data"))


def _setups(setups, n_modes):
    rows = []
    for s, setup in enumerate(setups, start=1):
        setup = setup if isinstance(setup, dict) else {}
        found = [m if isinstance(m, dict) else {} for m in setup.get("modes") or []]
        names = setup.get("sensor_names") or []
        rows.append([f"setup {s}", ", ".join(str(n) for n in names)]
                    + [number(found[j].get("frequency"), 5) if j < len(found) else "—"
                       for j in range(n_modes)])
    return html("<h3>Setups</h3><p>Each setup identified alone; the shapes merged by rescaling "
                "on the reference sensors, f and ξ averaged with inverse-variance weights.</p>{}",
                table(["setup", "sensors"] + [f"f mode {j + 1} [Hz]" for j in range(n_modes)],
                      rows, "data"))
