"""Simulation.to_xarray (issue 26 §2: records export to xarray where users expect them)."""

import sys

import numpy as np
import pytest
import xarray

from crowdvib import Simulation, simulate


def test_a_simulated_record_exports_its_samples_time_and_metadata(paper_bridge, paper_crowd,
                                                                  paper_msd):
    # issue 26 §2: dims output × time, the samples unchanged, units and the run in the attributes.
    record = simulate(paper_bridge, paper_crowd, 5.0, msd=paper_msd, sample_rate=50.0, rng=11)
    array = record.to_xarray()
    assert isinstance(array, xarray.DataArray)
    assert array.dims == ("output", "time") and array.name == "acceleration"
    np.testing.assert_array_equal(array.values, record.acceleration)
    # Sample times i / sample_rate from 0 (docs: theory, Conventions), in seconds.
    np.testing.assert_allclose(array.time.values, np.arange(250) / 50.0, rtol=0, atol=1e-12)
    assert array.time.attrs["units"] == "s" and array.attrs["units"] == "m/s²"
    np.testing.assert_array_equal(array.n_on_deck.values, record.n_on_deck)
    assert list(array.output.values) == ["midspan"]
    assert array.attrs["seed"] == 11 and array.attrs["sample_rate"] == 50.0
    assert array.attrs["hsi"] == 1 and array.attrs["n_pedestrians"] == record.n_pedestrians
    # The RMS over time is the record's own summary (the same samples, the same axis).
    rms = np.sqrt((array**2).mean("time")).values
    np.testing.assert_allclose(rms, record.summary()["rms"], rtol=1e-12)


def test_without_xarray_the_error_names_the_extra(monkeypatch):
    # issue 26 §2: an optional dependency, imported only when a record is exported.
    record = Simulation(time=None, acceleration=[[0.0, 0.1]], output_names=("mid",),
                        n_on_deck=[1, 1], sample_rate=100.0, seed=1, duration=0.02)
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ModuleNotFoundError, match=r"Simulation.to_xarray needs xarray.*"
                                                  r"crowdvib\[notebook\]"):
        record.to_xarray()
