"""Calibration of the likelihood of two outputs: per-output sum against the complex Wishart.

Gaussian two-output records with the model's cross-spectral matrix
(:func:`crowdvib.signals.synthesis.gaussian_cross_record`: exact complex-Wishart Welch statistics,
bin correlation included), one hour each, estimated three ways on the same records:

* ``sum`` — today's likelihood: the Whittle deviances of the two auto-PSDs added, intervals from
  the sandwich that takes the outputs as fully coherent;
* ``wishart`` — the complex-Wishart deviance of the Welch cross-spectral matrix
  (``welch_psd(..., cross=True)``);
* ``one output`` — the first output alone (the reference of a fully coherent pair).

Cases (truth f_h1 = 3.0 Hz, ξ_h1 = 0.30, μ_h1 = 0.95):

* ``paper`` — the paper's example bridge (one mode) with outputs at midspan and quarter span: one
  mode rules the band, the pair is fully coherent;
* ``beam3`` — the same beam with three modes (2, 8, 18 Hz): mode 1 still rules the band,
  modes 2 and 3 make the pair slightly less than fully coherent;
* ``eeklo`` — the Eeklo-like bridge (14 modes, band 2.5–8 Hz, T = 25 s), main and side span: each
  output sees its own modes, the pair is mostly incoherent (energy-weighted coherence 0.15);
* ``eeklo_quarter`` — the same bridge with outputs at the centre and the quarter of the main span
  (48 and 37.5 m): the 5.7 Hz mode rules both, the pair is partly coherent (0.83).

Prints, per case and estimator, the coverage of the truth by the 95 % profile interval, the mean
error with its 95 % interval, the standard deviation per record, the mean interval width (all
relative to the truth) and the time per estimate. Usage:
``python accuracy/wishart.py [paper|beam3|eeklo|eeklo_quarter] [N] [first seed]``;
``python accuracy/wishart.py timing`` times one estimate per case and estimator.
"""

import dataclasses
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from intervals import CROWD, MSD, TRUTH, _table  # noqa: E402

from crowdvib import BoundWarning, ModalModel, SpectralModel, estimate_hsi, welch_psd  # noqa: E402
from crowdvib.io.casefile import load_case  # noqa: E402
from crowdvib.signals.synthesis import gaussian_cross_record, record_frequencies  # noqa: E402

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")


def case(name):
    """(structure, crowd, outputs, band, window length [s], sample rate [Hz]) of a case."""
    if name in ("paper", "beam3"):
        bridge = ModalModel.simply_supported_beam(
            50.0, 3.0, 2.0, 0.005, 50e3, n_modes=1 if name == "paper" else 3,
            outputs={"midspan": 25.0, "quarter_span": 12.5})
        return bridge, CROWD, ("midspan", "quarter_span"), (0.0, 10.0), 60.0, 20.0
    eeklo = load_case(os.path.join(EXAMPLES, "eeklo_like.toml"))
    structure, outputs = eeklo.structure, ("main_span", "side_span")
    if name == "eeklo_quarter":
        outputs = ("main_span", "main_quarter")
        structure = structure.replace(output_names=outputs,
                                      output_shapes=structure.shapes_at(np.array([48.0, 37.5])))
    return structure, eeklo.crowd, outputs, (2.5, 8.0), 25.0, 20.0


def records(name, n, first=0, duration=3600.0):
    """Welch estimates (with cross-spectra) of n seeded Gaussian records of a case."""
    structure, crowd, outputs, band, window, rate = case(name)
    frequency = record_frequencies(duration, rate)
    cross = SpectralModel(structure, crowd, frequency, outputs=outputs).cross_psd_array(MSD)
    for seed in range(first, first + n):
        signals = gaussian_cross_record(cross, rate, rng=seed)
        yield welch_psd(signals, rate, window_length=window, output_names=outputs,
                        cross=True).band(0.0, 10.0)


def variants(measured):
    """The three estimators' inputs from one record."""
    return {"sum": dataclasses.replace(measured, cross=None), "wishart": measured,
            "one output": measured.select(measured.output_names[:1])}


def main(name="paper", n=200, first=0):
    structure, crowd, outputs, band, _, _ = case(name)
    rows = {(method, name): [] for method in ("sum", "wishart", "one output")}
    seconds = {key: 0.0 for key in rows}
    for measured in records(name, n, first):
        for method, data in variants(measured).items():
            started = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", BoundWarning)
                estimate = estimate_hsi(data, structure, crowd, band=band, method="likelihood")
            seconds[method, name] += time.perf_counter() - started
            rows[method, name].append([(getattr(estimate.msd, p), *estimate.interval(p))
                                       for p in TRUTH])
    print(f"case {name}: {n} Gaussian two-output records of one hour (seeds {first}–"
          f"{first + n - 1}), outputs {list(outputs)}, band {band} Hz, 95 % profile intervals; "
          f"load {os.getloadavg()[0]:.2f}")
    _table(rows, n, seconds)


def timing(repeats=5):
    """Median time per estimate (profile intervals) of each estimator on one record per case,
    the estimators interleaved within every repeat."""
    print(f"time per estimate with 95 % profile intervals, median of {repeats} interleaved "
          f"repeats; load {os.getloadavg()[0]:.2f}")
    for name in ("paper", "eeklo_quarter", "eeklo"):
        structure, crowd, _, band, _, _ = case(name)
        inputs = variants(next(records(name, 1, first=1000)))
        seconds = {method: [] for method in inputs}
        for _ in range(repeats):
            for method, data in inputs.items():
                started = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", BoundWarning)
                    estimate_hsi(data, structure, crowd, band=band, method="likelihood")
                seconds[method].append(time.perf_counter() - started)
        print(f"{name:14s}" + "".join(f"{method:>12s} {np.median(values):6.2f} s"
                                      for method, values in seconds.items()))
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__" and sys.argv[1:2] == ["timing"]:
    timing()
elif __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "paper",
         int(sys.argv[2]) if len(sys.argv) > 2 else 200,
         int(sys.argv[3]) if len(sys.argv) > 3 else 0)
