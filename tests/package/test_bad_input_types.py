"""Wrong types at the Python API get a crowdvib error naming the parameter (issue 24 §5).

On 49020a3 each case below ended in a foreign exception deep inside (AttributeError,
TypeError, IndexError), read a string or a complex number as a float without a word, or, for a
duration of 1e9 s, allocated memory for minutes before numpy gave up. The rule (architecture
§4): validate once at the public boundary; the message names the parameter, the rule and the
value.
"""

import numpy as np
import pytest

from crowdvib import (Crowd, ModalModel, MSDModel, ParameterError, effective_modal_properties,
                      estimate_hsi, frf, response_psd, simulate, simulate_many)
from crowdvib.design import tune_damper
from crowdvib.response.frequency_domain.spectral import modal_accelerance

pytestmark = pytest.mark.badinput

GRID = np.arange(0, 601) / 60.0          # the paper's Welch grid, T = 60 s, 0–10 Hz


def _model_calls(m):
    """Every public entry point that takes the models, as name → call(structure, crowd)."""
    return {
        "response_psd": lambda s, k: response_psd(s, k, GRID),
        "frf": lambda s, k: frf(s, GRID, crowd=k, msd=m),
        "effective_modal_properties": lambda s, k: effective_modal_properties(s, k, m),
        "modal_accelerance": lambda s, k: modal_accelerance(s, GRID, crowd=k, msd=m),
        "tune_damper": lambda s, k: tune_damper(s, 0, 0.02, crowd=k, msd=m),
    }


# (entry point, which argument is wrong); None for the crowd is legal where it is optional.
WRONG_MODELS = [(call, which, bad) for call in ("response_psd", "frf",
                                               "effective_modal_properties",
                                               "modal_accelerance", "tune_damper")
                for which in ("structure", "crowd") for bad in (None, {}, "bridge")
                if not (which == "crowd" and bad is None and call != "response_psd")]


@pytest.mark.parametrize("call, which, bad", WRONG_MODELS)
def test_a_model_of_the_wrong_type_is_named(paper_bridge, paper_crowd, paper_msd, call, which,
                                            bad):
    calls = _model_calls(paper_msd)
    structure, crowd = (bad, paper_crowd) if which == "structure" else (paper_bridge, bad)
    kind = "ModalModel" if which == "structure" else "Crowd"
    with pytest.raises(ParameterError, match=rf"{which} must be a {kind}, got "
                                             rf"{type(bad).__name__}"):
        calls[call](structure, crowd)


@pytest.mark.parametrize("label, call, pattern", [
    ("string frequencies", lambda b, c: response_psd(b, c, ["1", "2", "3"]),
     r"frequency must be numeric, got '1': a string is not read"),
    ("complex frequencies", lambda b, c: response_psd(b, c, np.array([1.0, 2.0, 3.0]) + 1j),
     r"frequency must be numeric, got \(1\+1j\): complex is not read"),
    ("string natural frequency",
     lambda b, c: ModalModel.simply_supported_beam(50.0, 3.0, "2", 0.005, 50e3),
     r"frequency must be numeric, got '2': a string is not read"),
    ("complex natural frequency",
     lambda b, c: ModalModel.simply_supported_beam(50.0, 3.0, 2 + 1j, 0.005, 50e3),
     r"frequency must be numeric, got \(2\+1j\): complex is not read"),
    ("string density", lambda b, c: Crowd("0.5", 1.3, 1.89),
     r"density must be numeric, got '0\.5': a string is not read"),
    ("string MSD frequency", lambda b, c: MSDModel("3"),
     r"frequency must be numeric, got '3': a string is not read"),
])
def test_strings_and_complex_numbers_are_not_read_as_floats(paper_bridge, paper_crowd, label,
                                                            call, pattern):
    # np.array("3", dtype=float) is 3.0 and a complex value loses its imaginary part with only a
    # ComplexWarning: _validation.as_float_array refuses both.
    with pytest.raises(ParameterError, match=pattern):
        call(paper_bridge, paper_crowd)


def test_frequency_weights_of_the_wrong_length(paper_bridge, paper_crowd, paper_msd):
    # One weight per measured frequency (601 on the Welch grid): 10 was an IndexError.
    measured = response_psd(paper_bridge, paper_crowd, GRID, msd=paper_msd)
    with pytest.raises(ParameterError, match=r"frequency_weights \(one per measured frequency\) "
                                             r"must have 601 entries, got 10"):
        estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                     frequency_weights=np.ones(10))


def test_a_record_that_will_not_fit_is_refused_at_once(paper_bridge, paper_crowd):
    # 1e9 s at 100 Hz is 1e11 samples of the one output and of the time axis, 8 bytes each:
    # 1.6e12 B, plus λ·T = 0.5 × 3 × 1.30 × 1e9 = 1.95e9 walkers. No machine has that; the
    # answer comes before any allocation (it took 13 GB and two minutes on 49020a3).
    with pytest.raises(ParameterError, match=r"duration = 1e\+09 s at sample_rate = 100 Hz "
                                             r"needs about .* GB \(1e\+11 samples × 2 rows, "
                                             r"1\.95e\+09 walkers per record\), more than half "
                                             r"the .* GB of memory"):
        simulate(paper_bridge, paper_crowd, 1e9)


def test_a_batch_that_will_not_fit_is_refused_at_once(paper_bridge, paper_crowd):
    # simulate_many keeps every record: 10 000 seeds × 1e6 s at 100 Hz × 2 rows × 8 B = 16 TB
    # of records alone, though each record (1.6 GB) would fit by itself.
    with pytest.raises(ParameterError, match=r"duration = 1e\+06 s at sample_rate = 100 Hz "
                                             r"for 10000 seeds needs about .* GB .*fewer seeds "
                                             r"at a time"):
        simulate_many(paper_bridge, paper_crowd, 1e6, seeds=list(range(10_000)))
