"""W_b frequency weighting (BS 6841 / ISO 10137) and the running RMS."""

import numpy as np
import pytest

from crowdvib import ParameterError
from crowdvib.signals.weighting import WB_CONSTANTS, running_rms, wb_response, weight_wb


def reference_wb(frequency):
    """Independent form of W_b: the BS 6841 weighting as one rational function in descending
    powers of s (as the public bs6841freqweight.m writes it),
    2πK f4² f6² (s + ω3)(s² + ω5 s/Q5 + ω5²) / (f3 f5² (s² + ω4 s/Q4 + ω4²)(s² + ω6 s/Q6 + ω6²)),
    times the second-order Butterworth band limits at 0.4 Hz and 100 Hz."""
    c = WB_CONSTANTS
    s = 2j * np.pi * np.asarray(frequency)
    w = {k: 2 * np.pi * c[k] for k in ("f1", "f2", "f3", "f4", "f5", "f6")}
    numerator = np.polyval(np.polymul([1, w["f3"]], [1, w["f5"] / c["q5"], w["f5"] ** 2]), s)
    denominator = np.polyval(np.polymul([1, w["f4"] / c["q4"], w["f4"] ** 2],
                                        [1, w["f6"] / c["q6"], w["f6"] ** 2]), s)
    weighting = (2 * np.pi * c["k"] * c["f4"] ** 2 * c["f6"] ** 2 * numerator
                 / (c["f3"] * c["f5"] ** 2 * denominator))
    band = (s**2 / np.polyval([1, np.sqrt(2) * w["f1"], w["f1"] ** 2], s)
            * w["f2"] ** 2 / np.polyval([1, np.sqrt(2) * w["f2"], w["f2"] ** 2], s))
    return weighting * band


@pytest.mark.parametrize("frequency", [0.5, 1.0, 2.0, 2.5, 4.0, 5.0, 8.0, 16.0, 31.5])
def test_wb_transfer_function_at_third_octave_frequencies(frequency):
    assert wb_response(frequency) == pytest.approx(reference_wb(frequency), rel=1e-12)


def test_wb_plateaus():
    # BS 6841 W_b: gain K = 0.4 between the band limit and the step, K (f6/f5)² = 1.024 above
    # it (before the transition at 16 Hz); the band-limited curve approaches both closely.
    assert abs(wb_response(1.2)) == pytest.approx(0.4, rel=0.05)
    assert abs(wb_response(8.0)) == pytest.approx(1.024, rel=0.05)


@pytest.mark.parametrize("frequency", [1.0, 2.0, 4.0, 8.0, 16.0])
def test_filter_gain_on_sines(frequency):
    # A long sine through the filter: its steady amplitude is |W_b(f)| times the input's.
    rate, duration = 200.0, 80.0
    t = np.arange(int(rate * duration)) / rate
    weighted = weight_wb(np.sin(2 * np.pi * frequency * t), rate)
    steady = weighted[t >= 40.0]
    gain = np.sqrt(2 * np.mean(steady**2))
    assert gain == pytest.approx(abs(reference_wb(frequency)), rel=2e-3)


def test_running_rms_parseval_on_a_sine():
    # Parseval: a 1 s window holding whole periods of A sin(2πft) has mean square A²/2 exactly.
    rate, amplitude = 100.0, 0.3
    t = np.arange(1000) / rate
    rms = running_rms(amplitude * np.sin(2 * np.pi * 2.0 * t + 0.4), rate, 1.0)
    assert rms.shape == (901,)
    assert rms == pytest.approx(np.full(901, amplitude / np.sqrt(2)), rel=1e-10)
    # And of any record: the window's mean square equals the direct mean of a² over it.
    noise = np.random.default_rng(3).normal(size=500)
    assert running_rms(noise, 50.0, 1.0)[7] == pytest.approx(np.sqrt(np.mean(noise[7:57]**2)))


def test_running_rms_bad_window():
    with pytest.raises(ParameterError, match="window × sample_rate must give 1 to 10 samples"):
        running_rms(np.zeros(10), 100.0, 1.0)
