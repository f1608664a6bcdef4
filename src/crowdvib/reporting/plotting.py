"""Figures. The only module that imports matplotlib, and only when a plot is asked for.

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``.
"""

from dataclasses import dataclass

import numpy as np

__all__ = ["FigureAxes", "plot_psd_comparison", "plot_psd_convergence", "plot_load_psd",
           "plot_hsi_effect", "plot_frf", "plot_objective_map", "plot_estimation_errors",
           "plot_parametric_ratios", "plot_time_history", "save_figure", "figure_bytes"]

# The paper's figures are black and gray; a colour-blind-safe dark/light pair keeps them legible
# on screen and in a grayscale print.
_DARK, _LIGHT = "black", "0.6"


@dataclass(frozen=True)
class FigureAxes:
    """The figure and axes of a multi-panel plot.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    axes : tuple of matplotlib.axes.Axes
        The panels, in reading order (left to right, top to bottom).
    """

    figure: object
    axes: tuple


def _pyplot():
    import matplotlib

    # A library must not pop up windows or need a display; Agg renders anywhere. force=False
    # keeps a backend the caller chose before importing pyplot.
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _axes(ax, figsize=(7.5, 4.2)):
    if ax is not None:
        return ax
    _, ax = _pyplot().subplots(figsize=figsize, layout="constrained")
    return ax


def _in_band(frequency, band):
    """Index of the frequencies within [lower, upper] [Hz]; everything for band None."""
    if band is None:
        return slice(None)
    return (frequency >= band[0]) & (frequency <= band[1])


def _panels(axes, nrows, ncols, figsize, **options):
    """Given panels (checked for their number) or a new figure of nrows × ncols."""
    if axes is not None:
        axes = tuple(np.ravel(axes))
        if len(axes) != nrows * ncols:
            from ..errors import ParameterError

            raise ParameterError(f"axes must hold {nrows * ncols} panels, got {len(axes)}")
        return FigureAxes(axes[0].figure, axes)
    figure, grid = _pyplot().subplots(nrows, ncols, figsize=figsize, layout="constrained",
                                      squeeze=False, **options)
    return FigureAxes(figure, tuple(grid.ravel()))


def plot_psd_comparison(curves, *, output=None, band=None, logscale=True, ax=None, title=None):
    """Acceleration PSDs of one output on one axes (paper Figs. 3, 12, 17, 20).

    Parameters
    ----------
    curves : dict of str to ResponsePSD
        Legend label → PSD; drawn in order (first: the measurement, as a black line).
    output : str, optional
        Output name (default the first output of the first curve).
    band : (float, float), optional
        Frequency range [Hz] to show.
    logscale : bool
        Logarithmic PSD axis.
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    styles = [dict(color="black", lw=1.0), dict(color="tab:red", lw=1.6, ls="--"),
              dict(color="0.55", lw=1.2), dict(color="tab:blue", lw=1.2, ls=":")]
    unit, top = None, 0.0
    for (label, psd), style in zip(curves.items(), styles * 4):
        name = output or psd.output_names[0]
        row = psd.select(name)
        keep = _in_band(row.frequency, band)
        values = row.psd[0][keep]
        ax.plot(row.frequency[keep], np.where(values > 0, values, np.nan) if logscale else values,
                label=label, **style)
        unit = row.unit
        top = max(top, float(np.nanmax(values, initial=0.0)))
    if logscale:
        ax.set_yscale("log")
        if top > 0:  # eight decades show every structural feature; below is numerical dust
            ax.set_ylim(top * 1e-8, top * 3)
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(f"Acceleration PSD [{unit}]")
    if title:
        ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax


def _positive(values):
    """Values with non-positive entries as NaN: a log axis would otherwise drop or warn."""
    values = np.asarray(values, dtype=float)
    return np.where(values > 0, values, np.nan)


def plot_load_psd(frequency, crowd, *, structure=None, force=None, ax=None, title=None):
    """PSD of the crowd's vertical walking load (paper Fig. 2).

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz], >= 0.
    crowd : Crowd
        Density, step-frequency distribution and body mass.
    structure : ModalModel, optional
        With a structure, the modal load PSD G_F,jj(f) = Ψ_jj s(f) of each mode [N²/Hz] (the
        paper's G_F); without, the crowd-load spectrum per unit influence s(f) [N²/Hz].
    force : ZivanovicForce or YoungForce, optional
        Walking force model (default Živanović 2007).
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    from ..models.loading import as_force_model

    force = as_force_model(force)
    frequency = np.asarray(frequency, dtype=float)
    ax = _axes(ax)
    if structure is None:
        curves = {"s(f), per unit influence": force.load_spectrum(frequency, crowd)}
        ylabel = "Load PSD s [N²/Hz]"
    else:
        modal = force.modal_load_psd(frequency, crowd, structure)
        curves = {f"mode {j + 1} ({structure.frequencies[j]:g} Hz)": modal[:, j, j]
                  for j in range(structure.n_modes)}
        ylabel = "Modal load PSD $G_F$ [N²/Hz]"
    for (label, values), color in zip(curves.items(), [_DARK, _LIGHT, "0.35", "0.8"] * 8):
        ax.plot(frequency, values, color=color, lw=1.4, label=label)
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(ylabel)
    ax.set_xlim(frequency.min(), frequency.max())
    ax.set_ylim(bottom=0)
    ax.set_title(title or f"Walking load, {crowd.density:g} persons/m², $f_s$ ~ "
                 f"N({crowd.step_frequency_mean:g}, {crowd.step_frequency_std:g}) Hz")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax


def _peak_zoom(rows, frequency):
    """A frequency window [Hz] around the PSD peaks of ``rows``, wide enough to show both."""
    peaks = [frequency[int(np.nanargmax(row))] for row in rows]
    centre, spread = 0.5 * (min(peaks) + max(peaks)), max(peaks) - min(peaks)
    half = max(0.15 * centre, 1.5 * spread, 2.0 * (frequency[1] - frequency[0]))
    return max(frequency[0], centre - half), min(frequency[-1], centre + half)


def plot_hsi_effect(without, with_hsi, *, output=None, band=None, zoom=None, axes=None,
                    title=None):
    """Response PSD without and with HSI, and an enlargement of the dominant peak (paper Fig. 3).

    Parameters
    ----------
    without, with_hsi : ResponsePSD
        Predicted PSDs with the crowd as moving forces only, and with the MSD model.
    output : str, optional
        Output name (default the first output of ``without``).
    band : (float, float), optional
        Frequency range [Hz] of the left panel (default all).
    zoom : (float, float), optional
        Frequency range [Hz] of the enlargement (default around the peaks).
    axes : sequence of two matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    FigureAxes
        ``axes`` = (full band, log scale; enlargement, linear scale).
    """
    handles = _panels(axes, 1, 2, (10.0, 4.0), width_ratios=(3, 2))
    full, detail = handles.axes
    name = output or without.output_names[0]
    curves = [("without HSI", without.select(name), dict(color=_DARK, lw=1.2)),
              ("with HSI", with_hsi.select(name), dict(color=_LIGHT, lw=1.8))]
    for label, row, style in curves:
        peak = row.peak_frequency()[0]
        keep = _in_band(row.frequency, band)
        full.plot(row.frequency[keep], _positive(row.psd[0][keep]),
                  label=f"{label} (peak {peak:.2f} Hz)", **style)
    top = max(float(np.nanmax(row.psd[0])) for _, row, _ in curves)
    full.set_yscale("log")
    full.set_ylim(top * 1e-8, top * 3)  # eight decades: below is numerical dust
    lower, upper = zoom or _peak_zoom([row.psd[0] for _, row, _ in curves], curves[0][1].frequency)
    full.axvspan(lower, upper, color="tab:blue", alpha=0.08, lw=0)
    for label, row, style in curves:
        keep = _in_band(row.frequency, (lower, upper))
        detail.plot(row.frequency[keep], row.psd[0][keep], label=label, **style)
    detail.set_xlim(lower, upper)
    detail.set_ylim(bottom=0)
    unit = curves[0][1].unit
    for ax, sub in ((full, "(a)"), (detail, "(b) enlargement")):
        ax.set_xlabel("Frequency [Hz]")
        ax.set_ylabel(f"Acceleration PSD [{unit}]")
        ax.set_title(sub, loc="left", fontsize="medium")
        ax.grid(True, which="both", alpha=0.3)
    full.legend()
    handles.figure.suptitle(title or f"Response at {name} without and with HSI")
    return handles


def plot_frf(empty, occupied=None, *, output=None, input=None, band=None, ax=None, title=None):
    """Accelerance FRF magnitude of the empty and the occupied structure (paper Figs. 9, 18).

    Parameters
    ----------
    empty : FRF
        From ``crowdvib.frf(structure, f)``.
    occupied : FRF, optional
        From ``crowdvib.frf(structure, f, crowd=crowd, msd=msd)``.
    output : str, optional
        Output point (default the first output of ``empty``).
    input : str, optional
        Input point (default the output: a driving-point FRF).
    band : (float, float), optional
        Frequency range [Hz] to show.
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    name = output or empty.output_names[0]
    source = name if input is None else input
    curves = [("empty", empty, dict(color=_DARK, lw=1.2, ls="--"))]
    if occupied is not None:
        curves.append(("with HSI" if occupied.occupied else "second FRF", occupied,
                       dict(color=_DARK, lw=1.6)))
    for label, result, style in curves:
        keep = _in_band(result.frequency, band)
        magnitude = result.magnitude(name, source)[keep]
        peak = result.frequency[keep][np.argmax(magnitude)]
        ax.plot(result.frequency[keep], _positive(magnitude),
                label=f"{label} (peak {peak:.2f} Hz)", **style)
    ax.set_yscale("log")
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(f"|H| [{empty.unit}]")
    ax.set_title(title or f"FRF, output {name}, input {source}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax


def _uncertainty_bounds(uncertainty):
    """Parameter → (nominal, bound) from a SensitivityResult or its ``summary()`` dict."""
    summary = uncertainty.summary() if hasattr(uncertainty, "summary") else uncertainty
    return {name: (float(summary[name]["nominal"]), float(summary[name]["bound"]))
            for name in ("frequency", "damping_ratio") if name in summary
            and summary[name].get("bound") is not None and np.isfinite(summary[name]["bound"])}


def plot_objective_map(objective_map, *, uncertainty=None, search_bounds=None, relative=True,
                       ax=None, title=None):
    """The objective J(f_h1, ξ_h1) with its optimum and bounds (paper Figs. 4 and 10).

    Parameters
    ----------
    objective_map : ObjectiveMap
        From :func:`crowdvib.identification.objective_map`.
    uncertainty : SensitivityResult or dict, optional
        A modelling-error study (or its ``summary()``): its nominal ± bound are drawn as dashed
        lines around the optimum (paper Fig. 10).
    search_bounds : dict, optional
        The estimator's bounds, parameter → (lower, upper), drawn as a dotted box.
    relative : bool
        Show J/J_noHSI (default) rather than J.
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
        The optimum marker carries the gid ``"optimum"``, the bounds ``"uncertainty"`` and
        ``"search_bounds"``.
    """
    from matplotlib.colors import LogNorm

    ax = _axes(ax, figsize=(7.0, 5.0))
    cost = np.asarray(objective_map.cost, dtype=float)
    scale = objective_map.cost_no_hsi if relative and objective_map.cost_no_hsi > 0 else 1.0
    values = cost / scale
    finite = values[np.isfinite(values) & (values > 0)]
    norm = None
    if finite.size and finite.max() > finite.min():
        # A noise-free map has J ≈ 0 at the truth; five decades below the largest J keep the
        # valley's shape visible instead of spending the whole scale on one grid point.
        norm = LogNorm(max(finite.min(), finite.max() * 1e-5), finite.max(), clip=True)
    mesh = ax.pcolormesh(objective_map.frequencies, objective_map.damping_ratios,
                         _positive(values), norm=norm, cmap="Greys_r", shading="nearest")
    if norm is not None and min(values.shape) > 1:
        levels = np.geomspace(norm.vmin, norm.vmax, 9)[1:-1]
        ax.contour(objective_map.frequencies, objective_map.damping_ratios, values,
                   levels=levels, colors="tab:blue", linewidths=0.6, alpha=0.7)
    colorbar = ax.figure.colorbar(mesh, ax=ax)
    colorbar.set_label("$J/J_{noHSI}$ [-]" if scale != 1.0 else "J [-]")
    best = objective_map.estimate if objective_map.estimate is not None else objective_map.optimum
    kind = "optimiser" if objective_map.estimate is not None else "grid"
    ax.plot([best.frequency], [best.damping_ratio], "o", color="tab:red", mec="white", ms=9,
            gid="optimum", label=f"optimum ({kind}): {best.frequency:.3f} Hz, "
                                 f"{best.damping_ratio:.3f}")
    if uncertainty is not None:
        bounds = _uncertainty_bounds(uncertainty)
        style = dict(color="tab:red", ls="--", lw=1.0, gid="uncertainty")
        first = True
        for name, line in (("frequency", ax.axvline), ("damping_ratio", ax.axhline)):
            if name in bounds:
                nominal, bound = bounds[name]
                for value in (nominal - bound, nominal + bound):
                    line(value, label="nominal ± bound" if first else None, **style)
                    first = False
    if search_bounds:
        from matplotlib.patches import Rectangle

        (f0, f1), (x0, x1) = search_bounds["frequency"], search_bounds["damping_ratio"]
        ax.add_patch(Rectangle((f0, x0), f1 - f0, x1 - x0, fill=False, ls=":", lw=1.2,
                               ec="tab:orange", gid="search_bounds", label="search bounds"))
    ax.set_xlim(objective_map.frequencies.min(), objective_map.frequencies.max())
    ax.set_ylim(objective_map.damping_ratios.min(), objective_map.damping_ratios.max())
    ax.set_xlabel("MSD natural frequency $f_{h1}$ [Hz]")
    ax.set_ylabel("MSD damping ratio $\\xi_{h1}$ [-]")
    ax.set_title(title or f"Objective function, $\\mu_{{h1}}$ = {objective_map.mass_ratio:g}")
    ax.legend(loc="upper right", fontsize="small")
    return ax


_PARAMETER_LABELS = {"frequencies": "$\\varepsilon_f$", "damping_ratios": "$\\varepsilon_\\xi$",
                     "modal_masses": "$\\varepsilon_m$",
                     "step_frequency_mean": "$\\varepsilon_{\\mu fs}$",
                     "step_frequency_std": "$\\varepsilon_{\\sigma fs}$", "joint": "joint"}


def _level_colors(n):
    """Dark for the lower error level, lighter for the higher ones (the paper's black/gray)."""
    return [str(v) for v in np.linspace(0.0, 0.6, max(n, 2))][:max(n, 1)]


def plot_estimation_errors(sensitivity, *, axes=None, title=None):
    """Estimation errors Δ per modelling-error case (paper Figs. 11 and 19).

    Each bar spans from 0 to the extreme errors of one group (a perturbed input at one error
    level, both signs; or all joint sign combinations at that level); the dots are the cases.

    Parameters
    ----------
    sensitivity : SensitivityResult or dict
        From :func:`crowdvib.identification.modelling_error_study` (or its ``to_dict()``).
    axes : sequence of two matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    FigureAxes
        ``axes`` = (Δ f_h1, Δ ξ_h1).
    """
    cases = sensitivity["cases"] if isinstance(sensitivity, dict) else sensitivity.cases
    done = [c for c in cases if "error" not in c and c["kind"] != "nominal"]
    failed = sum(1 for c in cases if "error" in c)
    groups, epsilons = [], {}
    for case in done:
        key = "joint" if case["kind"] == "joint" else case["perturbations"][0][0]
        if key not in groups:
            groups.append(key)
        if key != "joint":
            epsilons.setdefault(key, {})[case["level"]] = abs(case["perturbations"][0][1])
    levels = sorted({c["level"] for c in done})
    colors = dict(zip(levels, _level_colors(len(levels))))
    width = 0.8 / max(len(levels), 1)
    handles = _panels(axes, 1, 2, (11.0, 4.2))
    for ax, key, label in zip(handles.axes, ("delta_frequency", "delta_damping_ratio"),
                              ("$\\Delta f_{h1}$ [%]", "$\\Delta \\xi_{h1}$ [%]")):
        for i, group in enumerate(groups):
            for j, level in enumerate(levels):
                chosen = [c[key] for c in done if c["level"] == level and
                          ("joint" if c["kind"] == "joint" else c["perturbations"][0][0]) == group]
                if not chosen:
                    continue
                x = i + (j - (len(levels) - 1) / 2) * width
                low, high = min(0.0, min(chosen)), max(0.0, max(chosen))
                ax.bar(x, high - low, bottom=low, width=0.9 * width, color=colors[level],
                       edgecolor="black", lw=0.5,
                       label=f"level {level + 1}" if i == 0 else None)
                ax.plot(np.full(len(chosen), x), chosen, "_", color="tab:red", ms=8, mew=1.2)
        ax.axhline(0.0, color="black", lw=0.8)
        # Bars stick to their ends, so autoscaling would cut the extreme case marks in half.
        values = [c[key] for c in done] + [0.0]
        pad = 0.06 * (max(values) - min(values)) or 1.0
        ax.set_ylim(min(values) - pad, max(values) + pad)
        ax.set_xticks(range(len(groups)), [
            _PARAMETER_LABELS.get(g, g) + ("" if g not in epsilons else "\n" + " / ".join(
                f"{100 * epsilons[g][level]:g}" for level in sorted(epsilons[g])) + " %")
            for g in groups])
        ax.set_xlabel("Modelling error")
        ax.set_ylabel(label)
        ax.grid(True, axis="y", alpha=0.3)
    handles.axes[0].legend(title="error level", fontsize="small", loc="best")
    handles.axes[0].set_title("(a) natural frequency", loc="left", fontsize="medium")
    handles.axes[1].set_title("(b) damping ratio", loc="left", fontsize="medium")
    note = f" ({failed} case(s) failed and are not shown)" if failed else ""
    handles.figure.suptitle((title or "Estimation error due to modelling errors") + note)
    return handles


def plot_parametric_ratios(parametric, *, parameters=None, axes=None, title=None):
    """Ratio estimated/true of f_h1 and ξ_h1 across a family of structures (paper Figs. 5, 6).

    One row of panels per perturbed input and estimated parameter, one column per
    crowd-to-structure mass ratio μ_m. Markers tell the structure's damping ratio (open circle,
    multiplication sign, plus sign), the shade the error level (black lower, gray higher); a
    filled circle marks an optimum on an active bound, as in the paper.

    Parameters
    ----------
    parametric : ParametricResult or dict
        From :func:`crowdvib.identification.parametric_study` (or its ``to_dict()``).
    parameters : sequence of str, optional
        Perturbed inputs to show (default all in the result; the paper's Fig. 5 is
        ``("modal_masses", "damping_ratios", "frequencies")``, Fig. 6
        ``("step_frequency_mean", "step_frequency_std")``).
    axes : sequence of matplotlib.axes.Axes, optional
        2·len(parameters) × n_μm panels, row by row.
    title : str, optional

    Returns
    -------
    FigureAxes
    """
    rows = parametric["rows"] if isinstance(parametric, dict) else parametric.rows
    done = [r for r in rows if "error" not in r]
    if parameters is None:
        parameters = list(dict.fromkeys(r["parameter"] for r in done))
    mass_ratios = sorted({r["structure_mass_ratio"] for r in done})
    dampings = sorted({r["structure_damping"] for r in done})
    levels = sorted({r["level"] for r in done})
    colors = dict(zip(levels, _level_colors(len(levels))))
    markers = dict(zip(dampings, ["o", "x", "+", "s", "^", "v"] * 4))
    quantities = (("frequency_ratio", "$\\hat f_{h1}/f_{h1}$ [-]"),
                  ("damping_ratio_ratio", "$\\hat \\xi_{h1}/\\xi_{h1}$ [-]"))
    n_rows, n_cols = 2 * len(parameters), max(len(mass_ratios), 1)
    handles = _panels(axes, n_rows, n_cols, (3.6 * n_cols + 1.0, 2.3 * n_rows + 0.6),
                      sharex=True)
    for p, parameter in enumerate(parameters):
        for q, (key, ylabel) in enumerate(quantities):
            for c, mass_ratio in enumerate(mass_ratios):
                ax = handles.axes[(2 * p + q) * n_cols + c]
                for damping in dampings:
                    for level in levels:
                        chosen = sorted((r for r in done if r["parameter"] == parameter
                                         and r["level"] == level
                                         and np.isclose(r["structure_damping"], damping)
                                         and np.isclose(r["structure_mass_ratio"], mass_ratio)),
                                        key=lambda r: r["structure_frequency"])
                        if not chosen:
                            continue
                        x = [r["structure_frequency"] for r in chosen]
                        y = [r[key] for r in chosen]
                        marker = markers[damping]
                        ax.plot(x, y, marker=marker, ls="-", lw=0.6, ms=5,
                                color=colors[level], mfc="none" if marker == "o" else None,
                                label=f"$\\xi_1$ = {damping:.1%}, ε = ±{chosen[0]['epsilon']:.1%}")
                        active = [(xx, yy) for xx, yy, r in zip(x, y, chosen)
                                  if r.get("active_bounds")]
                        if active:
                            ax.plot(*np.transpose(active), "o", ls="none", ms=5,
                                    color=colors[level], gid="active_bounds",
                                    label="active bound")
                ax.axhline(1.0, color="tab:blue", lw=0.6)
                ax.grid(True, alpha=0.3)
                if c == 0:
                    ax.set_ylabel(ylabel)
                ax.set_title(f"{_PARAMETER_LABELS.get(parameter, parameter)}, "
                             f"$\\mu_m$ = {mass_ratio:.1%}", fontsize="medium")
                if 2 * p + q == n_rows - 1:
                    ax.set_xlabel("Footbridge frequency $f_1$ [Hz]")
            legend_ax = handles.axes[2 * p * n_cols + n_cols - 1]
            entries = dict(zip(*reversed(legend_ax.get_legend_handles_labels())))
            legend_ax.legend(entries.values(), entries.keys(), fontsize="x-small",
                             loc="best")
    handles.figure.suptitle(title or "Ratio of estimated to true MSD parameters")
    return handles


def _running_rms(signal, sample_rate, window):
    """Trailing running RMS over ``window`` seconds; NaN until the first window is full."""
    n = max(int(round(window * sample_rate)), 1)
    energy = np.concatenate([[0.0], np.cumsum(np.asarray(signal, dtype=float) ** 2)])
    result = np.full(np.size(signal), np.nan)
    if result.size >= n:
        result[n - 1:] = np.sqrt(np.maximum(energy[n:] - energy[:-n], 0.0) / n)
    return result


def plot_time_history(simulation, *, output=None, window=1.0, axes=None, title=None):
    """Simulated acceleration, its running RMS and the number of people on the deck.

    Parameters
    ----------
    simulation : Simulation
        Anything with ``time`` [s], ``acceleration`` (n_outputs, n_samples) [m/s²],
        ``output_names``, ``n_on_deck`` (n_samples,) and ``sample_rate`` [Hz].
    output : str, optional
        Output name (default the first).
    window : float
        Running-RMS window [s] (default 1 s).
    axes : sequence of two matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    FigureAxes
        ``axes`` = (acceleration with running RMS, people on the deck).
    """
    handles = _panels(axes, 2, 1, (9.0, 5.0), sharex=True, height_ratios=(2, 1))
    top, bottom = handles.axes
    names = tuple(simulation.output_names)
    name = output or names[0]
    if name not in names:
        from ..errors import ParameterError

        raise ParameterError(f"output must be one of {list(names)}, got {name!r}")
    signal = np.asarray(simulation.acceleration)[names.index(name)]
    time = np.asarray(simulation.time)
    rms = _running_rms(signal, simulation.sample_rate, window)
    top.plot(time, signal, color=_LIGHT, lw=0.4, label="acceleration")
    peak = np.nanmax(rms) if np.isfinite(rms).any() else np.nan
    top.plot(time, rms, color=_DARK, lw=1.4, label=f"{window:g} s running RMS (max {peak:.3g} m/s²)")
    top.set_ylabel("Acceleration [m/s²]")
    top.grid(True, alpha=0.3)
    top.legend(loc="upper right", fontsize="small")
    bottom.step(time, simulation.n_on_deck, where="post", color=_DARK, lw=1.0)
    bottom.set_ylabel("People on deck [-]")
    bottom.set_xlabel("Time [s]")
    bottom.set_ylim(bottom=0)
    bottom.grid(True, alpha=0.3)
    top.set_xlim(time[0], time[-1])
    handles.figure.suptitle(title or f"Simulated response at {name}")
    return handles


def save_figure(ax, path):
    """Write the figure of ``ax`` to ``path`` (format from the suffix) atomically, and close it.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or FigureAxes
        Any object with a ``figure``.
    path : str or pathlib.Path
        Target file; ``.png``, ``.svg`` and ``.pdf`` are the useful suffixes.

    Returns
    -------
    path
    """
    import matplotlib.pyplot as plt

    from .._files import atomic_path

    figure = ax.figure
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format=str(path).rsplit(".", 1)[-1], dpi=130)
    plt.close(figure)
    return path


def figure_bytes(ax, format="png", *, dpi=110):
    """The figure of ``ax`` encoded as PNG or SVG bytes, and the figure closed.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or FigureAxes
    format : {"png", "svg"}
    dpi : float
        Resolution of a PNG [dots per inch].

    Returns
    -------
    bytes
    """
    import io

    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    # A fixed date and no hash salt keep an SVG byte-identical between runs of the same data.
    metadata = {"Date": None} if format == "svg" else {"Software": None}
    ax.figure.savefig(buffer, format=format, dpi=dpi, metadata=metadata)
    plt.close(ax.figure)
    return buffer.getvalue()


def plot_psd_convergence(convergence, *, ax=None, title=None, level=0.10):
    """Convergence error ΔG_kT of a Welch PSD against record length (paper Fig. 15).

    Parameters
    ----------
    convergence : PSDConvergence
        From :func:`crowdvib.signals.psd_convergence`.
    ax : matplotlib.axes.Axes, optional
    title : str, optional
    level : float, optional
        A reference level drawn as a dashed line (the paper's 10 %); None for none.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    for name, row in zip(convergence.output_names, convergence.error):
        ax.plot(convergence.duration[:-1], 100 * row[:-1], marker="o", ms=3, label=name)
    if level is not None:
        ax.axhline(100 * level, color="0.5", ls="--", lw=1.0, label=f"{level:.0%}")
    ax.set_ylim(bottom=0)  # the error is a distance to the converged PSD: 0 is the goal
    ax.set_xlabel("Record length k·T [s]")
    ax.set_ylabel(f"ΔG ({convergence.norm}-norm, {convergence.band[0]:g}–"
                  f"{convergence.band[1]:g} Hz) [%]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax
