"""The figures of a report: the files a command wrote and those drawn from ``results.json``.

Only the figures ``results.json`` names are embedded (no directory listing), and only if each
name is a plain file name of a PNG or SVG file directly inside the results directory, so a
results file cannot pull any other file into the report.
"""

from pathlib import Path

import numpy as np

from .._files import child_path
from .html import Markup, html, label
from .paths import relative_path
from .reading import get, hsi, sensitivity, summary
from .plotting import figure_bytes, plot_psd_convergence
from ..signals import PSDConvergence
from ..models.pedestrian import MSDModel
from .plotting import plot_objective_map
from ..studies.landscape import ObjectiveMap
from .plotting import plot_estimation_errors
from .plotting import plot_parametric_ratios
from .design_plots import plot_damper_frf

__all__ = ["collect_figures", "caption"]

_CAPTIONS = {
    "psd_fit": "Measured PSD against the model without HSI and with the fitted MSD "
               "(paper Figs. 12, 17, 20).",
    "psd_convergence": "Convergence error ΔG of the Welch PSD with record length; dashed: the "
                       "paper's 10 % (Fig. 15).",
    "objective_map": Markup("Objective J/J<sub>noHSI</sub> over f<sub>h1</sub> and "
                            "ξ<sub>h1</sub> with the optimum; dashed lines, where drawn: "
                            "nominal ± bound (paper Figs. 4, 10)."),
    "estimation_errors": "Estimation error Δ caused by modelling errors, per perturbed input and "
                         "error level (paper Figs. 11, 19).",
    "parametric_ratios": "Ratio of estimated to true MSD parameters across the family of "
                         "structures; filled circles: optimum on a bound (paper Figs. 5, 6).",
    "psd": "Welch PSD of the simulated record at every output.",
    "time_history": "Simulated acceleration with its 1 s running RMS and the people on the deck.",
    "design_utilisation": "Governing utilisation a/a_limit of each design check without HSI, "
                          "with the crowd's mass and with HSI; dashed: the limit.",
    "stabilisation": "SSI-cov stabilisation diagram: poles per model order, stable ones "
                     "filled; red lines: the identified modes; dashed, where drawn: stable "
                     "columns not reported.",
    "mode_shapes": "Identified mode shapes at the sensors, each 1 at its largest component.",
    "singular_values": "EFDD: singular values of the output spectral matrix; shaded: the SDOF "
                       "bells, red lines: the identified modes.",
    "design_modes": "Peak acceleration of every mode at the governing output, per code and "
                    "model; dashed: the limit.",
    "damper_frf": "Accelerance |H| of the governing mode at the governing output per unit "
                  "modal force, without the tuned mass damper (dashed) and with it, with the "
                  "model and crowd density of the check with the largest utilisation: the "
                  "damper splits the resonant peak into two lower ones.",
    "comfort_hours": "Hours a year in each comfort class (CL1 light … CL4 dark) per model of "
                     "the structure, without and with the damper; error marks: the band of the "
                     "identified MSD's interval (HSI rows) or of the season's sampling.",
    "comfort_exceedance": "Probability that a window's peak exceeds CL1's 0.5 m/s² against the "
                          "crowd density, per model.",
    "comfort_week": "Expected comfort class (1 = CL1 … 4 = CL4) in each hour of the week, "
                    "without and with the damper.",
    "comfort_peaks": "The window's peak against the crowd density per model: median (line) to "
                     "99 % quantile (shade), with the comfort classes' bounds.",
}
_PNG = b"\x89PNG\r\n\x1a\n"


def collect_figures(results, directory, notes, convergence_level):
    """(name, mime type, bytes, caption) of every figure: the listed files, then drawn ones."""
    figures, names = [], []
    if directory is not None:
        listed = [n for n in results.get("figures") or [] if isinstance(n, str)]
        for name in dict.fromkeys(listed):
            path = child_path(directory, name)
            name = relative_path(name, None)      # shown without the machine's folders
            if path is None or path.suffix.lower() not in (".png", ".svg"):
                notes.warn(html("figure {} is not a PNG or SVG file of the results directory "
                                "and is left out.", name))
                continue
            if not path.is_file():
                notes.warn(html("figure {} is listed in results.json but missing.", name))
                continue
            data = path.read_bytes()
            mime = "image/svg+xml" if path.suffix.lower() == ".svg" else "image/png"
            if mime == "image/png" and not data.startswith(_PNG):
                notes.warn(html("figure {} is not a PNG file and is left out.", name))
                continue
            figures.append((name, mime, data, caption(name)))
            names.append(path.stem)
    drawers = (("psd_convergence", _draw_convergence), ("objective_map", _draw_map),
               ("estimation_errors", _draw_errors), ("parametric_ratios", _draw_parametric),
               ("damper_frf", _draw_damper_frf))
    for stem, draw in drawers:
        if stem in names:
            continue
        try:
            image = (draw(results, convergence_level) if stem == "psd_convergence"
                     else draw(results))
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as error:
            notes.warn(html("the {} figure could not be drawn from results.json: {}: {}",
                            label(stem), type(error).__name__, str(error)))
            continue
        if image is not None:
            figures.append((f"{stem}.png (drawn from results.json)", "image/png", image,
                            caption(stem)))
    return figures


def caption(name):
    """The caption of a figure file (Markup)."""
    stem = Path(name).stem
    if stem in _CAPTIONS:
        return html("{}", _CAPTIONS[stem])
    if stem.startswith("psd_"):
        return html("PSD at {}: measured against the model without HSI and with the fitted MSD "
                    "(paper Figs. 12, 17, 20).", stem[4:])
    if stem.startswith("time_history_"):
        return html("Simulated acceleration at {} with its 1 s running RMS and the people on the "
                    "deck.", stem[len("time_history_"):])
    for kind in ("stabilisation", "singular_values"):
        if stem.startswith(kind + "_setup"):
            return html("{} (setup {})", _CAPTIONS[kind], stem[len(kind) + 6:])
    if stem.startswith("residuals_"):
        return html("Relative residuals of the joint fit at {}, against the 95 % band of the "
                    "Welch scatter: residuals outside it in many neighbouring bins are what the "
                    "model does not explain.", stem[10:])
    return html("{}", stem.replace("_", " "))


def _draw_convergence(results, level):
    data = hsi(results, "convergence")
    if not isinstance(data, dict) or "error" not in data:
        return None
    convergence = PSDConvergence(
        n_windows=np.asarray(data["n_windows"]), duration=np.asarray(data["duration"], float),
        error=np.atleast_2d(np.asarray(data["error"], float)),
        output_names=tuple(data["output_names"]), window_length=data["window_length"],
        band=tuple(data["band"]), norm=str(data.get("norm", "2")))
    return figure_bytes(plot_psd_convergence(convergence, level=level))


def _draw_map(results):
    data = get(results, ("objective_map",), ("map",))
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
    bounds = hsi(results, "bounds")
    search = bounds if isinstance(bounds, dict) and {"frequency", "damping_ratio"} <= set(bounds) \
        else None
    return figure_bytes(plot_objective_map(objective, uncertainty=summary(results),
                                           search_bounds=search))


def _draw_errors(results):
    study = sensitivity(results)
    if study is None or not any(isinstance(c, dict) and "delta_frequency" in c
                                for c in study["cases"]):
        return None
    return figure_bytes(plot_estimation_errors(study))


def _draw_parametric(results):
    data = get(results, ("parametric",))
    if data is None and isinstance(results.get("rows"), list):
        data = results
    if not isinstance(data, dict) or not any(isinstance(r, dict) and "frequency_ratio" in r
                                             for r in data.get("rows", [])):
        return None
    return figure_bytes(plot_parametric_ratios(data))


def _draw_damper_frf(results):
    data = get(results, ("design", "frf"))
    if not isinstance(data, dict) or not isinstance(data.get("with_damper"), list):
        return None
    return figure_bytes(plot_damper_frf(data))
