"""``crowdvib check``: the design checks of a case's ``[design]`` table, without and with HSI.

For every code of ``design.codes`` the case's structure is checked with
:func:`crowdvib.design.design_check` (no HSI, added mass, and HSI with the case's MSD, or the MSD
another run estimated: ``--msd-from``), optionally with a tuned mass damper, and the case's crowd
stream is predicted with :func:`crowdvib.design.predict_response`. The results directory holds
``results.json`` (every check in full and a verdict table), the figures and ``report.html``.
"""

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from .._version import __version__
from .._files import write_json
from ..reporting.report import provenance, write_report
from .common import (DESIGN_TABLES, add_output_arguments, case_inputs, say, say_verdict,
                     staged_output, versions, warning_texts)

__all__ = ["add_arguments", "run", "verdict_rows"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", type=Path, help="case file (TOML) with a [design] table")
    add_output_arguments(parser)
    parser.add_argument("--msd-from", type=Path, default=None, metavar="RESULTS",
                        help="results directory of `crowdvib estimate` (or demo, sensitivity): "
                             "its estimated MSD replaces the case's for the HSI model")


def run(args: argparse.Namespace) -> int:
    # The warnings of the case and of the checks go into results.json, hence into the verdict:
    # ξ = 0.5 for 0.5 % must not pass a failing bridge with "no warnings" (issue 24).
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        return _run(args, caught)


def _run(args, caught):
    from ..errors import ParameterError
    from ..io.casefile import load_case

    case = load_case(args.case)
    spec = case.design
    if spec is None:
        raise ParameterError(f"{args.case.name}: crowdvib check needs a [design] table "
                             "(design.codes at least)")
    _check_design_table(case.path, spec)
    msd, msd_source = _msd(case, spec, args.msd_from)
    inputs = case_inputs(case) + ([] if args.msd_from is None
                                  else [("the MSD results", args.msd_from / "results.json")])
    say(f"crowdvib check: {case.name}, codes {', '.join(spec.codes)}, "
        f"{'HSI from ' + msd_source if msd is not None else 'no HSI'}")
    with staged_output(args.out, args.force, command="check", inputs=inputs) as staging:
        started = time.perf_counter()
        dampers = _dampers(case, spec, msd)
        checks = {code: _check(case, spec, code, msd, dampers) for code in spec.codes}
        prediction = None
        if spec.prediction:
            from ..design.stochastic import predict_response

            crowd = (case.crowd if spec.density is None
                     else case.crowd.with_density(spec.density))
            prediction = predict_response(case.structure, crowd, msd=msd, dampers=dampers,
                                          duration=spec.duration, weighting=spec.weighting)
        elapsed = time.perf_counter() - started
        figures = _figures(checks, staging, case.name)
        rows = verdict_rows(checks)
        results = {"command": "check", "crowdvib_version": __version__, "versions": versions(),
                   "case": str(case.path), "inputs": case.to_dict(DESIGN_TABLES),
                   "msd": None if msd is None else {**msd.to_dict(), "source": msd_source},
                   "design": {"verdict": rows,
                              "checks": {code: check.to_dict() for code, check in checks.items()},
                              "dampers": [d.to_dict() for d in dampers],
                              "prediction": None if prediction is None else prediction.to_dict()},
                   "elapsed_s": elapsed, "figures": figures, **provenance(case.path),
                   "warnings": list(dict.fromkeys(warning_texts(caught)))}   # once each
        for text in results["warnings"]:
            print(f"crowdvib check: warning: {text}", file=sys.stderr)
        write_json(staging / "results.json", results)
        write_report(staging)
    for line in _table_lines(rows):
        say("  " + line)
    if prediction is not None:
        for model, rms, peak in zip(prediction.models, prediction.rms, prediction.expected_peak):
            say(f"  crowd stream, {model}: RMS {_join(rms)} m/s², expected peak over "
                f"{prediction.duration:g} s {_join(peak)} m/s²")
    say(f"  wrote results.json, {', '.join(figures)} and report.html to {args.out} "
        f"({elapsed:.1f} s)")
    say_verdict(args.out)
    return 0


def _join(values):
    return "/".join(f"{v:.3f}" for v in np.atleast_1d(values))


def _msd(case, spec, msd_from):
    """The MSD of the HSI model and where it comes from (None without HSI)."""
    from ..errors import DataError
    from ..models.pedestrian import MSDModel
    from ..reporting.reading import estimate, read_results

    if msd_from is not None:
        found = estimate(read_results(Path(msd_from) / "results.json"))
        if not found or not {"frequency", "damping_ratio"} <= set(found):
            raise DataError(f"--msd-from {msd_from}: its results.json holds no MSD estimate")
        mass_ratio = found.get("mass_ratio") or case.msd.mass_ratio
        return (MSDModel(found["frequency"], found["damping_ratio"], mass_ratio),
                f"the estimate in {msd_from}")
    if not spec.hsi:
        return None, None
    if spec.msd is not None:
        return spec.msd, "[design.msd]"
    return case.msd, "[hsi]"


def _check_design_table(path, spec):
    """Refuse, against the case file and before anything is written, the ``[design]`` values
    only the design layer can judge: the registered codes (and a class given per code), the
    comfort class, the UK NA site factors (io reads the table without importing ``design``,
    issue 26 §4)."""
    from ..design import code_names
    from ..design.codes import COMFORT_CLASSES, ukna_limit
    from ..errors import ParameterError

    def refused(rule):
        return ParameterError(f"{path.name}: design.{rule}")

    if any(code not in code_names() for code in spec.codes):
        raise refused(f"codes must list codes among {list(code_names())}, got {list(spec.codes)}")
    for code in spec.classes:
        if code not in spec.codes:
            raise refused(f"classes.{code} is given but {code!r} is not in design.codes "
                          f"{list(spec.codes)}")
    classes = [name for name, _ in COMFORT_CLASSES[:-1]]
    if spec.comfort_class is not None and spec.comfort_class not in classes:
        raise refused(f"comfort_class must be one of {classes}, got {spec.comfort_class!r}")
    try:
        ukna_limit(spec.site_factors)
    except ParameterError as exc:
        raise refused(str(exc)) from None


def _dampers(case, spec, msd):
    """The ``[design.damper]`` as a list (tuned to the occupied structure when HSI is on)."""
    from ..design import TunedMassDamper, tune_damper

    damper = spec.damper
    if damper is None:
        return []
    if "mode" in damper:
        if damper["mode"] > case.structure.n_modes:
            from ..errors import ParameterError

            raise ParameterError(f"{case.path.name}: design.damper.mode must be at most the "
                                 f"number of modes ({case.structure.n_modes}), got "
                                 f"{damper['mode']}")
        crowd = case.crowd if msd is not None else None
        return [tune_damper(case.structure, damper["mode"] - 1, damper["mass_ratio"],
                            crowd=crowd, msd=msd)]
    return [TunedMassDamper(**damper)]


def _check(case, spec, code, msd, dampers):
    from ..design import design_check

    traffic_class = spec.classes.get(code)
    density = spec.density
    if traffic_class is None and density is None:
        density = case.crowd.density            # no class: the case's own crowd
    options = {}
    if code == "ukna":
        options = {"site_factors": spec.site_factors, "weighting": spec.weighting}
    elif code in ("setra", "hivoss"):
        options = {"comfort_class": spec.comfort_class}
    return design_check(case.structure, code, traffic_class=traffic_class, density=density,
                        crowd=case.crowd, msd=msd, dampers=dampers, **options)


def verdict_rows(checks: dict) -> list[dict]:
    """One row per code, model and output: governing acceleration, limit, utilisation, class."""
    labels = {"empty": "no HSI", "added_mass": "added mass", "hsi": "HSI"}
    rows = []
    for code, check in checks.items():
        for model in check.models:
            governing = check.governing_of(model)
            for output, value in zip(check.output_names, governing):
                rows.append({"code": code, "traffic_class": check.traffic_class,
                             "model": labels[model], "output": output,
                             "governing": float(value), "limit": float(check.limit),
                             "utilisation": float(value / check.limit),
                             "comfort_class": _comfort(value),
                             "passes": bool(value <= check.limit)})
    return rows


def _comfort(value):
    from ..design.codes import comfort_class

    return comfort_class(float(value))


def _table_lines(rows):
    header = (f"{'code':7s} {'class':5s} {'model':10s} {'output':12s} {'a [m/s²]':>9s} "
              f"{'limit':>6s} {'util.':>6s} {'comfort':>7s}")
    lines = [header]
    for row in rows:
        lines.append(f"{row['code']:7s} {row['traffic_class'] or '-':5s} {row['model']:10s} "
                     f"{row['output'][:12]:12s} {row['governing']:9.3f} {row['limit']:6.2f} "
                     f"{row['utilisation']:6.2f} {row['comfort_class']:>7s}"
                     f"{'' if row['passes'] else '  FAILS'}")
    return lines


def _figures(checks, staging, name):
    from ..reporting.design_plots import plot_mode_accelerations, plot_utilisation
    from .._figures import save_figure

    return [save_figure(plot_utilisation(checks, title=f"{name}: design checks"),
                        staging / "design_utilisation.png").name,
            save_figure(plot_mode_accelerations(checks, title=f"{name}: peak acceleration per "
                                                "mode"), staging / "design_modes.png").name]
