"""The comfort measures of simulated windows: the check of the spectral route, and its stand-in
where the response is not Gaussian (docs: theory, A year of comfort; validation).

:func:`simulated_windows` walks the crowd over the deck in the time domain
(:func:`crowdvib.simulate`: a Poisson stream of moving forces and, with an MSD, moving MSDs)
and cuts records into windows of T seconds, each reduced to its peak |a| and its largest running
RMS at one output. A task simulates ``windows_per_task`` consecutive windows after a warm-up
(the windows of one record are as independent as a crowd's memory of a crossing allows: a
crossing of the paper's bridge takes 40 s, a window 600 s); the tasks run on the runner's pool
or a dask cluster (:func:`crowdvib.runner.run_tasks`), each with its own seed drawn from the
user's. :func:`simulated_check` sets their quantiles beside the spectral ones per density.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import check_count, check_positive, fields_from_dict
from ..errors import ParameterError
from ..runner.tasks import run_tasks
from .measure import GAUSSIAN_TOLERANCE, peak_quantile, running_rms_quantile, window_law
from .year import QUANTILES
from ..response.time_domain.simulation import simulate
from ..signals.weighting import running_rms
from ..design.stochastic import frequency_grid
from ..response.frequency_domain.fluctuation import spectral_model

__all__ = ["SimulatedWindows", "simulated_windows", "simulated_check", "GAUSSIAN_TOLERANCE"]



@dataclass(frozen=True)
class _Task:
    """One task: ``count`` windows of one crowd state, simulated from ``seed``."""

    structure: object
    crowd: object
    msd: object
    dampers: tuple
    output: int
    duration: float
    rms_window: float
    sample_rate: float
    warm_up: float
    count: int
    seed: int


def _windows(task):
    """The peaks and largest running RMS of a task's windows (JSON-ready)."""
    import time


    started = time.process_time()
    found = simulate(task.structure, task.crowd, task.duration * task.count, msd=task.msd,
                     sample_rate=task.sample_rate, rng=task.seed, warm_up=task.warm_up,
                     dampers=list(task.dampers) or None)
    size = int(round(task.duration * task.sample_rate))
    windows = found.acceleration[task.output][:size * task.count].reshape(task.count, size)
    rms = running_rms(windows, task.sample_rate, task.rms_window).max(axis=-1)
    return {"peak": np.abs(windows).max(axis=-1).tolist(), "running_rms": rms.tolist(),
            "cpu": time.process_time() - started}


@dataclass(frozen=True)
class SimulatedWindows:
    """The windows simulated at each density.

    Attributes
    ----------
    densities : tuple of float
    peak, running_rms : tuple of ndarray
        Per density, each window's peak |a| and largest running RMS [m/s²].
    cpu : float
        CPU time of the simulations, summed over the tasks [s].
    """

    densities: tuple
    peak: tuple
    running_rms: tuple
    cpu: float = 0.0

    def to_dict(self) -> dict:
        """JSON-ready: the densities, each window's peak and largest running RMS, the CPU."""
        return {"densities": list(self.densities), "peak": [p.tolist() for p in self.peak],
                "running_rms": [r.tolist() for r in self.running_rms], "cpu": self.cpu}

    @classmethod
    def from_dict(cls, data: dict) -> SimulatedWindows:
        """The windows of :meth:`to_dict`.

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not a dict or lacks a field.
        """
        def arrays(rows):
            return tuple(np.asarray(row, dtype=float) for row in rows)

        found = data if isinstance(data, dict) else {}
        return fields_from_dict(cls, data, peak=arrays(found.get("peak", ())),
                                running_rms=arrays(found.get("running_rms", ())))


def simulated_windows(structure, crowd, densities, *, msd=None, dampers=None, output=0,
                      n_windows: int = 500, duration: float = 600.0, rms_window: float = 1.0,
                      sample_rate: float = 100.0, warm_up: float = 100.0,
                      windows_per_task: int = 10, seed: int = 0, executor=None,
                      progress=None) -> SimulatedWindows:
    """``n_windows`` simulated windows at each density (module docstring).

    Parameters
    ----------
    structure, crowd
        The empty bridge and the walkers (each density replaces the crowd's).
    densities : sequence of float
        [persons/m²], > 0.
    msd : MSDModel, optional
        The walkers' MSD (None: moving forces only, no HSI).
    dampers : sequence of TunedMassDamper, optional
    output : int
        Index of the output judged.
    n_windows, duration, rms_window
        Windows per density, T [s] and τ [s].
    sample_rate, warm_up
        Of the simulation [Hz], [s].
    windows_per_task : int
        Consecutive windows of one simulated record (one task).
    seed : int
        The user's seed; task k of density i draws from SeedSequence(seed, (i, k)).
    executor : concurrent.futures.Executor, optional
        Where the tasks run (:func:`crowdvib.runner.study_executor`); default this process.
    progress : callable, optional
        ``progress(done, total)`` in tasks.
    """
    n_windows = check_count("n_windows", n_windows, minimum=1)
    windows_per_task = check_count("windows_per_task", windows_per_task, minimum=1)
    duration = check_positive("duration", duration, unit="s")
    check_positive("sample_rate", sample_rate, unit="Hz")
    densities = [check_positive("density", d, unit="persons/m²") for d in densities]
    seed = check_count("seed", seed)
    tasks = []
    for i, density in enumerate(densities):
        here = crowd.with_density(density)
        left, k = n_windows, 0
        while left > 0:
            count = min(windows_per_task, left)
            state = int(np.random.SeedSequence(seed, spawn_key=(i, k)).generate_state(1)[0])
            tasks.append((f"d{i}-{k}", _Task(structure, here, msd, tuple(dampers or ()), output,
                                              duration, rms_window, sample_rate, warm_up,
                                              count, state)))
            left, k = left - count, k + 1
    results = run_tasks(_windows, tasks, executor=executor, progress=progress,
                        fields=("peak", "running_rms"))
    failed = [name for name, found in results.items() if "error" in found]
    if failed:
        raise ParameterError(f"{len(failed)} simulation task(s) failed, e.g. {failed[0]}: "
                             f"{results[failed[0]]['error']}")
    peaks, rms = [], []
    for i in range(len(densities)):
        mine = [results[name] for name, _ in tasks if name.startswith(f"d{i}-")]
        peaks.append(np.concatenate([found["peak"] for found in mine]))
        rms.append(np.concatenate([found["running_rms"] for found in mine]))
    cpu = float(sum(found.get("cpu", 0.0) for found in results.values()))
    return SimulatedWindows(tuple(densities), tuple(peaks), tuple(rms), cpu)


def simulated_check(structure, crowd, densities, *, msd=None, dampers=None, output=0,
                    duration: float = 600.0, rms_window: float = 1.0,
                    peak_model: str = "vanmarcke", crowd_model: str | None = None,
                    simulated: SimulatedWindows | None = None, **options) -> list[dict]:
    """Per density, the quantiles (:data:`~crowdvib.comfort.year.QUANTILES`) of the window's peak
    and largest running RMS, spectral against simulated.

    Parameters
    ----------
    structure, crowd, densities, msd, dampers, output, duration, rms_window
        As :func:`simulated_windows`.
    peak_model, crowd_model
        Of the spectral route (:func:`crowdvib.comfort.comfort_year`).
    simulated : SimulatedWindows, optional
        Windows already simulated (else :func:`simulated_windows` with ``options``).

    Returns
    -------
    list of dict
        Per density: ``density``, ``n_windows``, ``spectral_peak``, ``simulated_peak``,
        ``spectral_running_rms``, ``simulated_running_rms`` (one value per quantile),
        ``peak_error`` and ``running_rms_error`` (relative, spectral/simulated − 1),
        ``peak_interval`` and ``running_rms_interval`` (the simulated quantiles' distribution-free
        95 % intervals: order statistics of ranks from the binomial law), ``gaussian`` (every
        spectral quantile within :data:`GAUSSIAN_TOLERANCE` of the simulated one or inside its
        interval: the windows cannot tell them apart), and the spectral ``rms``.
    """

    if simulated is None:
        simulated = simulated_windows(structure, crowd, densities, msd=msd, dampers=dampers,
                                      output=output, duration=duration, rms_window=rms_window,
                                      **options)
    q = np.array(QUANTILES)
    rows = []
    for density, peaks, rms in zip(simulated.densities, simulated.peak, simulated.running_rms):
        here = crowd.with_density(density)
        grid = frequency_grid(structure, here, msd, list(dampers or ()))
        model = spectral_model(structure, here, grid, dampers=dampers,
                               **({"crowd_model": crowd_model} if crowd_model else {}))
        law = window_law(model.frequency, model.psd_array(msd)[output], rms_window=rms_window)
        spectral = peak_quantile(q, law, duration, peak_model)
        spectral_rms = running_rms_quantile(q, law, duration)
        sim, sim_rms = np.quantile(peaks, q), np.quantile(rms, q)
        errors = spectral / sim - 1
        rms_errors = spectral_rms / sim_rms - 1
        ends, rms_ends = _quantile_interval(peaks, q), _quantile_interval(rms, q)
        agree = [(abs(e) <= GAUSSIAN_TOLERANCE) | ((low <= s) & (s <= high))
                 for e, s, (low, high) in ((errors, spectral, ends),
                                           (rms_errors, spectral_rms, rms_ends))]
        rows.append({"density": float(density), "n_windows": int(peaks.size),
                     "spectral_peak": spectral.tolist(), "simulated_peak": sim.tolist(),
                     "spectral_running_rms": spectral_rms.tolist(),
                     "simulated_running_rms": sim_rms.tolist(),
                     "peak_error": errors.tolist(), "running_rms_error": rms_errors.tolist(),
                     "peak_interval": [list(pair) for pair in zip(*ends)],
                     "running_rms_interval": [list(pair) for pair in zip(*rms_ends)],
                     "gaussian": bool(np.all(np.concatenate(agree))),
                     "spectral_rms": law.rms})
    return rows



def _quantile_interval(values, q, level=0.95):
    """Distribution-free ``level`` intervals of the q-quantiles of ``values``: the order
    statistics whose ranks bound Binomial(n, q) (David & Nagaraja, Order Statistics, §7.1)."""
    from scipy import stats

    ordered = np.sort(values)
    n = ordered.size
    tail = (1 - level) / 2
    low = np.clip(stats.binom.ppf(tail, n, q).astype(int) - 1, 0, n - 1)
    high = np.clip(stats.binom.ppf(1 - tail, n, q).astype(int), 0, n - 1)
    return ordered[low], ordered[high]
