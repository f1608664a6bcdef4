"""The verdict on a result: the same findings in Python, on the console and in report.html.

:func:`findings` judges what a results.json holds (any command's, through the look-ups of
:mod:`crowdvib.cases.schema`) and returns a tuple of :class:`Finding`: ``"ok"`` confirms a check
passed, ``"doubt"`` says to check before use, ``"fail"`` says the result answers no (a design
check that fails). ``result.verdict()`` (:mod:`crowdvib.cases.results`), the command line's
verdict line and the report's summary box all print these, in this order.

Texts are plain; symbols are written ``f_h1``, ``ξ_h1``, ``J/J_noHSI`` (the report typesets the
subscripts). Light on purpose (no numpy): the command line imports it.
"""

from typing import NamedTuple

from .schema import get, hsi, real, sensitivity
from ..design.registry import code_label

__all__ = ["Finding", "findings", "in_doubt", "is_doubt", "fails_design", "CONVERGENCE_LEVEL",
           "RELATIVE_COST_LEVEL", "SEVERITIES"]

#: The paper's convergence criterion for a Welch PSD (Fig. 15): ΔG below 10 %.
CONVERGENCE_LEVEL = 0.10
#: J/J_noHSI above this means the MSD explains little of the misfit without HSI. The paper's fits
#: reach below 1 % (Eeklo) and 2 % (Waalse Krook); 10 % leaves room for real data.
RELATIVE_COST_LEVEL = 0.10
#: From good to bad.
SEVERITIES = ("ok", "doubt", "fail")

_RELATIVE = "J/J_noHSI"


class Finding(NamedTuple):
    """One finding of a verdict.

    Attributes
    ----------
    severity : str
        ``"ok"`` (a check passed), ``"doubt"`` (check before use) or ``"fail"``.
    text : str
        The finding in words (plain text, one sentence or two).
    key : str
        The results.json key it concerns, dotted (e.g. ``"diagnostics.relative_cost"``).
    """

    severity: str
    text: str
    key: str

    def __str__(self):
        return self.text


def _g(x, digits=4):
    """A number as the report's tables show it (``—`` for none or non-finite)."""
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if real(x) is not None:
        return f"{x:.{digits}g}"
    return "—" if x is None or isinstance(x, float) else str(x)


def findings(results: dict) -> tuple[Finding, ...]:
    """The verdict on a results dict: every finding of every rule, in the report's order.

    Parameters
    ----------
    results : dict
        What a results.json holds (``Results.to_dict()``); keys it lacks are not judged.

    Returns
    -------
    tuple of Finding
    """
    found = []
    for rule in _RULES:
        found += rule(results)
    return tuple(found)


def _relative_cost(results):
    relative = real(hsi(results, "relative_cost"))
    if relative is None:
        return []
    key = _where(results, "relative_cost")
    if relative > RELATIVE_COST_LEVEL:
        return [Finding("doubt", f"{_RELATIVE} = {_g(relative, 3)} is above "
                        f"{RELATIVE_COST_LEVEL:.0%}: the MSD model explains little of the misfit "
                        "without HSI.", key)]
    return [Finding("ok", f"the fit removes {100 * (1 - relative):.2f} % of the misfit without "
                    f"HSI ({_RELATIVE} = {_g(relative, 3)}).", key)]


def _optimiser(results):
    success = hsi(results, "success")
    if success is None or success:
        return []
    return [Finding("doubt", f"the optimiser did not converge: {hsi(results, 'message') or ''}",
                    _where(results, "success"))]


def _active_bounds(results):
    active = hsi(results, "active_bounds")
    if not isinstance(active, list) or not active:
        return []
    names = ", ".join(str(a) for a in active)
    return [Finding("doubt", f"the optimum sits on a bound ({names}): widen the bounds or "
                    "distrust that parameter.", _where(results, "active_bounds"))]


def _convergence(results):
    """The paper's Fig. 15 criterion on the change the last Welch window made, per output."""
    convergence = hsi(results, "convergence")
    if not isinstance(convergence, dict) or "error" not in convergence:
        return []
    key = _where(results, "convergence")
    rows = convergence["error"]
    rows = rows if isinstance(rows, list) and rows and isinstance(rows[0], list) else [rows]
    if not all(isinstance(row, list) and row and all(real(v) is not None for v in row)
               for row in rows):
        return [Finding("doubt", "the PSD convergence in results.json is not numeric and is "
                        "left out.", key)]
    names = convergence.get("output_names")
    names = names if isinstance(names, list) else [f"output {i + 1}" for i in range(len(rows))]
    found = []
    # The last entry is 0 by construction (the full record against itself); the one before is
    # the change that adding the last window made.
    for name, row in zip(names, rows):
        change = row[-2] if len(row) > 1 else row[0]
        if change >= CONVERGENCE_LEVEL:
            found.append(Finding("doubt", f"the PSD of {name} has not converged: the last window "
                                 f"changed it by {100 * change:.1f} % (≥ "
                                 f"{CONVERGENCE_LEVEL:.0%}); use a longer record.", key))
        else:
            found.append(Finding("ok", f"PSD of {name} converged (last change "
                                 f"{100 * change:.1f} %).", key))
    return found


def _record_length(results):
    rows = results.get("record_length")
    rows = [r for r in rows if isinstance(r, dict) and "duration" in r] \
        if isinstance(rows, list) else []
    failed = [r for r in rows if "error" in r]
    if not failed:
        return []
    return [Finding("doubt", f"{len(failed)} record-length re-estimation(s) failed, e.g. "
                    f"{failed[0]['error']}", "record_length")]


def _season(results):
    """A season's rows: failed ones, ones in doubt (their estimate raised warnings, as a
    record's own would: issue 36 §1), and a joint estimate that failed, are doubts."""
    rows = [r for r in results.get("records") or [] if isinstance(r, dict) and "status" in r]
    found = []
    for status, what in (("error", "failed"), ("doubt", "are in doubt")):
        chosen = [r for r in rows if r["status"] == status]
        if chosen:
            found.append(Finding("doubt", f"{len(chosen)} of {len(rows)} row(s) of the season "
                                 f"{what}, e.g. {chosen[0].get('name')}: "
                                 f"{chosen[0].get('warnings')}", "records"))
    if results.get("joint_error"):
        found.append(Finding("doubt", f"the joint estimate failed: {results['joint_error']}",
                             "joint_error"))
    return found


def _study(results):
    study = sensitivity(results)
    if not study:
        return []
    cases = [c for c in study["cases"] if isinstance(c, dict)]
    failed = [c for c in cases if "error" in c]
    found = []
    if failed:
        found.append(Finding("doubt", f"{len(failed)} modelling-error case(s) failed, e.g. "
                             f"{failed[0].get('name', '?')}: {failed[0]['error']}",
                             "sensitivity.cases"))
    # A case on a search bound has a Δ the bound cut short: the study's bound is then a lower
    # limit, which the verdict must say.
    stuck = [c for c in cases if isinstance(c.get("active_bounds"), list) and c["active_bounds"]]
    if stuck:
        first = stuck[0]
        found.append(Finding(
            "doubt", f"{len(stuck)} of {len(cases)} modelling-error case(s) ended on a search "
            f"bound (e.g. {first.get('label') or first.get('name', '?')}: "
            f"{', '.join(map(str, first['active_bounds']))}): their Δ is cut short by the "
            "bound, so the modelling bound is a lower limit; widen the search bounds.",
            "sensitivity.cases"))
    return found


def _run_warnings(results):
    messages = results.get("warnings")
    messages = messages if isinstance(messages, list) else []
    return [Finding("doubt", str(message), "warnings") for message in messages]


def _design(results):
    """A check that fails with the primary model (HSI when checked, else no HSI) fails."""

    rows = get(results, ("design", "verdict"))
    if not isinstance(rows, list):
        return []
    rows = [r for r in rows if isinstance(r, dict)]
    primary = "HSI" if any(r.get("model") == "HSI" for r in rows) else "no HSI"
    return [Finding("fail", f"{code_label(r.get('code'))} {r.get('traffic_class') or ''} fails at "
                    f"{r.get('output')} with {primary}: {_g(r.get('governing'), 3)} m/s² above "
                    f"the limit {_g(r.get('limit'), 3)} m/s² (utilisation "
                    f"{_g(r.get('utilisation'), 3)}).", "design.verdict")
            for r in rows if r.get("model") == primary and r.get("passes") is False]


def _interval(results):
    """``crowdvib check --msd-from`` (issue 27 §3): per code, the HSI verdict over the estimate's
    interval. A code that passes at the estimate but fails at the conservative end of the
    interval (the highest utilisation over the box of f_h1 and ξ_h1) fails there: the data do
    not decide it, so it is also in doubt (:func:`in_doubt`). A code failing at the estimate
    is :func:`_design`'s."""
    ranges = results.get("hsi_range")
    if not isinstance(ranges, dict):
        return []

    found = []
    for code, row in ranges.items():
        row = row if isinstance(row, dict) else {}
        point, low, high = (real(row.get(key)) for key in ("utilisation", "low", "high"))
        if point is None or high is None or point > 1.0:
            continue
        over = f"the {row.get('interval') or 'estimate'} interval of f_h1 and ξ_h1"
        span = f"{_g(low, 3)}–{_g(high, 3)}"
        if high <= 1.0:
            found.append(Finding("ok", f"{code_label(code)} passes over {over} (utilisation "
                                       f"{span}).",
                                 f"hsi_range.{code}"))
            continue
        end = row.get("conservative_end") if isinstance(row.get("conservative_end"), dict) else {}
        at = (f" (f_h1 = {_g(end.get('frequency'), 3)} Hz, ξ_h1 = "
              f"{_g(end.get('damping_ratio'), 3)})" if end else "")
        found.append(Finding(
            "fail", f"{code_label(code)} passes at the estimate (utilisation {_g(point, 3)}) but "
            "fails at the "
            f"conservative end of {over}{at}: utilisation {_g(high, 3)} there (range {span}).",
            f"hsi_range.{code}"))
    return found


def is_doubt(finding) -> bool:
    """Whether a finding doubts the result: a ``"doubt"``, or a ``"fail"`` the data do not
    decide (a design code that passes at the estimate and fails at the conservative end of its
    interval). A code the bridge fails at the estimate is an answer, not a doubt."""
    return finding.severity == "doubt" or (finding.severity == "fail"
                                           and finding.key.startswith("hsi_range."))


def in_doubt(found) -> bool:
    """Whether a verdict doubts its result (any finding :func:`is_doubt`): the command line
    exits with status 3 (docs: Command line, Exit status).

    Parameters
    ----------
    found : sequence of Finding
        A verdict (:func:`findings`).

    Returns
    -------
    bool
    """
    return any(is_doubt(f) for f in found)


def fails_design(found) -> bool:
    """Whether the bridge fails a design code at the result (a ``"fail"`` that is no doubt): an
    answer of the checks, exit status 4 when the result itself is not in doubt (docs: Command
    line, Exit status)."""
    return any(f.severity == "fail" and not is_doubt(f) for f in found)


_METHODS = {"ssi-cov": "SSI-cov", "efdd": "EFDD"}


def method_name(method):
    """The display name of an OMA method (``"ssi-cov"`` → ``"SSI-cov"``)."""
    return _METHODS.get(method, str(method))


def _modes(results):
    """``crowdvib modes``: a mode the second method does not confirm (beyond ``level`` combined
    standard deviations, or not found) is a doubt."""
    modes, check = results.get("modes"), results.get("cross_check")
    if (results.get("command") != "modes" or not isinstance(modes, list)
            or not isinstance(check, dict) or not isinstance(check.get("modes"), list)):
        return []
    modes = [m if isinstance(m, dict) else {} for m in modes]
    method, other = method_name(results.get("method", "ssi-cov")), method_name(check.get("method"))
    level = check.get("level", 1.96)
    found = []
    for j, (mine, row) in enumerate(zip(modes, check["modes"])):
        row = row if isinstance(row, dict) else {}
        if row.get("agree") is True:
            continue
        if row.get("frequency") is None:
            found.append(Finding("doubt", f"mode {j + 1} ({_g(mine.get('frequency'))} Hz): the "
                                 f"cross-check by {other} finds no mode there.", "cross_check"))
        else:
            found.append(Finding(
                "doubt", f"mode {j + 1}: {method} and {other} disagree beyond {_g(level, 3)} "
                f"combined σ: Δf = {_g(row.get('frequency_difference'), 2)} Hz (z = "
                f"{_g(row.get('frequency_z'), 2)}), Δξ = {_g(row.get('damping_difference'), 2)} "
                f"(z = {_g(row.get('damping_z'), 2)}).", "cross_check"))
    pairs = min(len(modes), len(check["modes"]))
    if not found and pairs:
        found.append(Finding("ok", f"{other} confirms all {pairs} modes of {method} within "
                             f"{_g(level, 3)} combined σ.", "cross_check"))
    return found


def _where(results, key):
    """The dotted key an estimator key was found under."""
    return key if key in results else f"diagnostics.{key}"


_RULES = (_relative_cost, _optimiser, _active_bounds, _convergence, _record_length, _study,
          _season, _run_warnings, _design, _interval, _modes)
