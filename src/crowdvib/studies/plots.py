"""Figures of the studies: the objective landscape, the modelling errors and the parametric study
(paper Figs. 4–6, 10, 11, 19), drawn by the results' ``plot()``.

Every function takes result objects and an optional ``ax`` or ``axes``, returns them and never
calls ``plt.show()``; matplotlib is imported only when a plot is asked for
(:mod:`crowdvib._figures`). All figures are importable from :mod:`crowdvib.reporting.plotting`.
"""

import numpy as np

from .._figures import axes_or_new, panels, positive_or_nan

__all__ = ["plot_objective_map", "plot_estimation_errors", "plot_parametric_ratios",
           "plot_season_trends"]


def _uncertainty_bounds(uncertainty):
    """Parameter → (nominal, bound) from a SensitivityResult or its ``summary()`` dict."""
    summary = uncertainty.summary() if hasattr(uncertainty, "summary") else uncertainty
    return {name: (float(summary[name]["nominal"]), float(summary[name]["bound"]))
            for name in ("frequency", "damping_ratio") if name in summary
            and summary[name].get("bound") is not None and np.isfinite(summary[name]["bound"])}


def plot_objective_map(objective_map, *, uncertainty=None, search_bounds=None, relative=True,
                       ax=None, title=None):
    """The objective J(f_h1, ξ_h1) with its optimum and bounds (paper Figures 4 and 10).

    Parameters
    ----------
    objective_map : ObjectiveMap
        From :func:`crowdvib.studies.objective_map`.
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

    ax = axes_or_new(ax, figsize=(7.0, 5.0))
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
                         positive_or_nan(values), norm=norm, cmap="Greys_r", shading="nearest")
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
    """Estimation errors Δ per modelling-error case (paper Figures 11 and 19).

    Each bar spans from 0 to the extreme errors of one group (a perturbed input at one error
    level, both signs; or all joint sign combinations at that level); the dots are the cases.

    Parameters
    ----------
    sensitivity : SensitivityResult or dict
        From :func:`crowdvib.studies.modelling_error_study` (or its ``to_dict()``).
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
    handles = panels(axes, 1, 2, (11.0, 4.2))
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
    """Ratio estimated/true of f_h1 and ξ_h1 across a family of structures (paper Figures 5 and 6).

    One row of panels per perturbed input and estimated parameter, one column per
    crowd-to-structure mass ratio μ_m. Markers tell the structure's damping ratio (open circle,
    multiplication sign, plus sign), the shade the error level (black lower, gray higher); a
    filled circle marks an optimum on an active bound, as in the paper.

    Parameters
    ----------
    parametric : ParametricResult or dict
        From :func:`crowdvib.studies.parametric_study` (or its ``to_dict()``).
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
    handles = panels(axes, n_rows, n_cols, (3.6 * n_cols + 1.0, 2.3 * n_rows + 0.6),
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


def plot_season_trends(rows, *, joint=None, axes=None, title=None):
    """A monitoring season's trends: f_h1 and ξ_h1 against density and against time.

    One point per record (or window) with its interval as an error bar; records in doubt are
    drawn open, and the joint estimate of the whole season is a line with its interval as a band.

    Parameters
    ----------
    rows : sequence of dict
        The season's table (:meth:`crowdvib.studies.SeasonResult.table`, or the ``records`` of
        a season's results.json): ``density``, ``time`` (ISO 8601, else the rows' order),
        ``frequency``, ``damping_ratio``, their ``_low``/``_high`` ends and ``status``.
    joint : HSIEstimate or dict, optional
        The joint estimate, or its ``"estimate"`` dict (value and ``interval``).
    axes : sequence of four matplotlib.axes.Axes, optional
        (f_h1 against density, ξ_h1 against density, f_h1 against time, ξ_h1 against time).
    title : str, optional

    Returns
    -------
    FigureAxes
    """
    import datetime

    done = [row for row in rows if row.get("status") in ("ok", "doubt")]
    if joint is not None and not isinstance(joint, dict):
        joint = joint.to_dict()["estimate"]
    times = [row.get("time") for row in done]
    dated = bool(done) and all(times)
    when = ([datetime.datetime.fromisoformat(t) for t in times] if dated
            else [i + 1 for i, _ in enumerate(done)])
    handles = panels(axes, 2, 2, (11.0, 7.0))
    quantities = (("frequency", "$f_{h1}$ [Hz]"), ("damping_ratio", "$\\xi_{h1}$ [-]"))
    for column, (key, label) in enumerate(quantities):
        for row_index, (xs, xlabel) in enumerate(((
                [row["density"] for row in done], "density [persons/m²]"),
                (when, "time" if dated else "record"))):
            ax = handles.axes[2 * row_index + column]
            for doubt in (False, True):
                chosen = [(x, row) for x, row in zip(xs, done)
                          if (row["status"] == "doubt") == doubt]
                if not chosen:
                    continue
                x = [c[0] for c in chosen]
                y = np.array([c[1][key] for c in chosen], dtype=float)
                low = np.array([np.nan if c[1][f"{key}_low"] is None else c[1][f"{key}_low"]
                                for c in chosen], dtype=float)
                high = np.array([np.nan if c[1][f"{key}_high"] is None
                                 else c[1][f"{key}_high"] for c in chosen], dtype=float)
                error = np.nan_to_num(np.vstack([y - low, high - y]))
                ax.errorbar(x, y, yerr=error, fmt="o", ms=4, capsize=2, lw=0.8,
                            color="tab:gray" if doubt else "tab:blue",
                            mfc="none" if doubt else None, gid="records",
                            label="record in doubt" if doubt else "record, 95 % interval")
            if joint is not None and key in joint:
                ax.axhline(joint[key], color="black", lw=1.2, gid="joint",
                           label="joint estimate")
                ends = (joint.get("interval") or {}).get(key)
                if ends and None not in ends:
                    ax.axhspan(*ends, color="black", alpha=0.12, lw=0)
            ax.set_xlabel(xlabel)
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
            if dated and row_index == 1:
                ax.tick_params(axis="x", labelrotation=30)
    if handles.axes[0].get_legend_handles_labels()[0]:    # no row estimated: no legend to draw
        handles.axes[0].legend(fontsize="small", loc="best")
    skipped = len(rows) - len(done)
    note = f" ({skipped} row(s) not estimated are not shown)" if skipped else ""
    handles.figure.suptitle((title or "A season of monitoring: the MSD's trends") + note)
    return handles
