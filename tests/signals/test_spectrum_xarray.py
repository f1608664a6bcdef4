"""ResponsePSD.to_xarray (issue 26 §2: spectra export to xarray where users expect them)."""

import sys

import numpy as np
import pytest
import xarray

from crowdvib import LowPassFilter, ResponsePSD, welch_psd


def test_a_welch_psd_exports_its_values_coordinates_and_units():
    # issue 26 §2: dims output × frequency, the values unchanged, the units in the attributes.
    rng = np.random.default_rng(7)
    record = rng.standard_normal((2, 6000))                       # 60 s at 100 Hz
    psd = welch_psd(record, 100.0, window_length=10.0, output_names=("mid", "quarter"),
                    lowpass=LowPassFilter(cutoff=20.0, order=4, sample_rate=100.0))
    array = psd.to_xarray()
    assert isinstance(array, xarray.DataArray)
    assert array.dims == ("output", "frequency") and array.name == "psd"
    np.testing.assert_array_equal(array.values, psd.psd)
    np.testing.assert_array_equal(array.frequency.values, psd.frequency)
    assert list(array.output.values) == ["mid", "quarter"]
    np.testing.assert_array_equal(array.sel(output="quarter").values, psd.select("quarter").psd[0])
    assert array.attrs["units"] == "(m/s²)²/Hz" and array.frequency.attrs["units"] == "Hz"
    assert array.attrs["window_length"] == 10.0 and array.attrs["n_windows"] == psd.n_windows == 11
    assert array.attrs["lowpass_cutoff"] == 20.0 and array.attrs["source"] == "welch"
    # The band variance is ∫ G df (docs: theory, Conventions): xarray's trapezoid over its
    # frequency coordinate gives ResponsePSD.variance, so the coordinate is the PSD's own grid.
    np.testing.assert_allclose(array.integrate("frequency").values, psd.variance(), rtol=1e-12)
    # A copy: the exported array can be changed without touching the frozen PSD.
    array[0, 0] = -1.0
    assert psd.psd[0, 0] >= 0


def test_a_model_psd_without_welch_settings_has_only_the_attributes_it_knows():
    # issue 26 §2: attributes a netCDF file can hold, so no None for an unknown window length.
    array = ResponsePSD([1.0, 2.0], [[0.1, 0.3]], ("midspan",)).to_xarray()
    assert array.attrs == {"units": "(m/s²)²/Hz", "long_name": "one-sided acceleration PSD",
                           "source": "model"}


def test_without_xarray_the_error_names_the_extra(monkeypatch):
    # issue 26 §2: an optional dependency, imported only here; a None entry in sys.modules makes
    # ``import xarray`` fail as it does where xarray is not installed.
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ModuleNotFoundError, match=r"ResponsePSD.to_xarray needs xarray.*"
                                                  r"crowdvib\[notebook\]"):
        ResponsePSD([1.0, 2.0], [[0.1, 0.3]], ("midspan",)).to_xarray()


def test_a_measured_record_exports_as_a_simulated_one_does(tmp_path):
    # issue 36 §1: the measured Record had no to_xarray. Read back from a file as `estimate`
    # reads it: dims (output, time) as Simulation.to_xarray; time = start + n / f_samp.
    from crowdvib.io import Record, read_record, write_record

    rng = np.random.default_rng(36)
    written = Record(rng.standard_normal((2, 500)), 50.0, ("mid", "quarter"), start_time=4.0)
    record = read_record(write_record(written, tmp_path / "record.npz"))
    array = record.to_xarray()
    assert array.dims == ("output", "time") and array.name == "acceleration"
    np.testing.assert_array_equal(array.values, written.data)
    np.testing.assert_allclose(array.time.values, 4.0 + np.arange(500) / 50.0, rtol=0,
                               atol=1e-12)
    assert list(array.output.values) == ["mid", "quarter"]
    assert array.attrs["units"] == "m/s²" and array.time.attrs["units"] == "s"
    assert array.attrs["sample_rate"] == 50.0 and array.attrs["duration"] == 10.0
    assert array.attrs["source"].endswith("record.npz")
    array[0, 0] = 99.0                                   # a copy: the record is frozen
    assert record.data[0, 0] == written.data[0, 0]
