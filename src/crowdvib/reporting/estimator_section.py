"""The estimator's settings and the optimiser's details in words, out of the inputs a client
reads (issue 27 §4: "status 2", "convergence norm 2", "match welch yes" are the estimator's
internals, not inputs of the bridge).

:func:`client_inputs` leaves out of the Inputs section what is no input there: the estimator's
internal switches (shown here instead, in a details section), the ``[hsi]`` defaults of
parameters the run estimated (all of ``[hsi]`` for a check that used another MSD), a structure
name the file did not set (the case file's name) and a default time column no record was read
by; it adds to the ``[design]`` card the checked codes' defaults not verified against their
guide.
"""

from markupsafe import Markup

from ..cases.schema import estimate, hsi
from ..identification.multistart import JOINED
from .design_section import design_inputs
from .html import html, join, number, table, value

__all__ = ["client_inputs", "estimator_details", "convergence_norm_words", "STATUS"]

#: ``scipy.optimize.least_squares`` status of a start, in words (scipy's documentation).
STATUS = {-1: "stopped: improper input", 0: "stopped at the evaluation limit",
          1: "converged: gradient below its tolerance",
          2: "converged: cost change below its tolerance",
          3: "converged: step below its tolerance",
          4: "converged: cost change and step below their tolerances",
          JOINED: "stopped: in the basin of an earlier start's optimum"}

#: ``[estimation]`` switches moved to the details, each (key, sentence per value).
_SWITCHES = {
    "match_welch": {True: "The model PSD is taken through the measurement's Welch window, "
                          "overlap and low-pass filter, as the measured PSD was "
                          "(estimation.match_welch).",
                    False: "The model PSD is the exact spectrum, not taken through the "
                           "measurement's Welch window and low-pass filter "
                           "(estimation.match_welch = false)."},
    "convergence_norm": {"2": "PSD convergence is the root-mean-square change of the PSD over "
                              "the band (2-norm; estimation.convergence_norm).",
                         "inf": "PSD convergence is the largest change of the PSD at any "
                                "frequency of the band (maximum norm; "
                                "estimation.convergence_norm)."}}

#: Record formats read as text tables, the only ones a time column can name.
_TEXT = (".csv", ".txt", ".tsv", ".dat")


def convergence_norm_words(norm):
    """The PSD convergence measure of ``norm`` ("2" or "inf") in words."""
    return {"2": "root-mean-square change", "inf": "largest change"}.get(str(norm),
                                                                       f"{norm}-norm change")


def client_inputs(results, name, block, not_set):
    """The rows of input card ``name`` a client reads (see the module docstring)."""
    if name == "estimation":
        return {k: v for k, v in block.items() if k not in _SWITCHES}
    if name == "structure" and not_set.get("structure.name") == "default":
        # Not set: the case file's name, which the case card shows already (issue 36 §3).
        return {k: v for k, v in block.items() if k != "name"}
    if name == "design":
        return design_inputs(results, block)
    if name == "hsi":
        msd = results.get("msd") if isinstance(results.get("msd"), dict) else {}
        if results.get("command") == "check" and msd.get("source") not in (None, "[hsi]"):
            # The check used another MSD (an estimate, [design.msd]): [hsi] was not (issue
            # 36 §3), and its values beside the MSD used would read as a second model.
            return {"not used": f"the MSD model of the check is {msd['source']} (below)"}
        found = estimate(results) or {}
        return {k: v for k, v in block.items()
                if not (k in found and not_set.get(f"hsi.{k}") == "default")}
    if name == "measurement" and not_set.get("measurement.time_column") == "default":
        # The default column name matters only where the rate came from a text table's time
        # stamps: a text record and no stated sample rate.
        files = block.get("files") if isinstance(block.get("files"), list) else []
        text = (str(block.get("format") or "").lower() in ("csv", "text")
                or any(str(f).lower().endswith(_TEXT) for f in files))
        if not (text and block.get("sample_rate") is None):
            return {k: v for k, v in block.items() if k != "time_column"}
    return block


def estimator_details(results):
    """A closed details section: the estimator's switches and every start of the optimiser,
    in words; empty without either."""
    estimation = (results.get("inputs") or {}).get("estimation") \
        if isinstance(results.get("inputs"), dict) else None
    sentences = [html("<li>{}</li>", _sentence(key, estimation[key]))
                 for key in _SWITCHES if isinstance(estimation, dict) and key in estimation]
    parts = [html("<ul>{}</ul>", join(sentences))] if sentences else []
    starts = hsi(results, "starts")
    if isinstance(starts, list) and starts:
        rows = [[value(s.get("start")), value(s.get("estimate")), number(s.get("cost"), 3),
                 number(s.get("n_evaluations")), _status(s.get("status"))]
                for s in starts[:20] if isinstance(s, dict)]
        parts.append(html("<p>The optimiser ran from {} starting point(s); the estimate is the "
                          "best of them.</p>{}", len(starts),
                          table(["start", "estimate", "cost J", "evaluations", "how it ended"],
                                rows, "data")))
        if len(starts) > 20:
            parts.append(html('<p class="muted">… and {} more.</p>', len(starts) - 20))
    if not parts:
        return Markup("")
    return html("<details><summary>Estimator details</summary>{}</details>", join(parts))


def _sentence(key, data):
    words = _SWITCHES[key].get(data) if isinstance(data, (str, bool)) else None
    return words or html("estimation.{} = {}", key, value(data))


def _status(status):
    if isinstance(status, int) and not isinstance(status, bool) and status in STATUS:
        return html("{} ({})", STATUS[status], status)
    return number(status)
