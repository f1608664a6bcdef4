"""Open extension points (issue 26 §3): a walking-force model written outside the package, and
the force chosen by a case file (docs: theory, The walking force)."""

from pathlib import Path

import numpy as np
import pytest

from crowdvib import (ParameterError, YoungForce, ZivanovicForce, estimate_hsi,
                      response_psd, simulate)
from crowdvib.io.casefile import load_case
from crowdvib.io.femodes import read_fe_modes
from crowdvib.io.formats import file_formats, suffix_format
from crowdvib.io.records import RECORD_FORMATS, Record, read_record, write_record
from crowdvib.models.loading import STANDARD_GRAVITY, ForceModel
from crowdvib.models.measured import MeasuredForce
from tests.io.test_casefile import write_case

WINDOW = 60.0                      # Welch T [s] (docs: theory, Welch PSDs, filters and convergence)
GRID = np.arange(0, 601) / WINDOW  # the Welch grid up to 10 Hz


class SingleHarmonic:
    """A user's force model, no crowdvib base class: the first harmonic only, the same DLF α for
    everybody, a uniform phase. Its crowd-load PSD per unit influence is closed form
    (docs: theory, Modal load PSD of a Poisson crowd, with one component r = 1):
    s(f) = E[W²] α²/2 · p_fs(f)."""

    def __init__(self, dlf=0.4):
        self.dlf = dlf

    @property
    def ratios(self):
        return np.array([1.0])

    def sample(self, step_frequency, rng):
        n = np.asarray(step_frequency).size
        return np.full((n, 1), self.dlf), rng.uniform(0.0, 2 * np.pi, (n, 1))

    def load_spectrum(self, frequency, crowd):
        frequency = np.asarray(frequency, dtype=float)
        return crowd.mean_square_weight() * self.dlf**2 / 2 * crowd.step_frequency_pdf(frequency)


def test_user_force_is_a_force_model():
    # The protocol is structural: the three members the package calls (docs: theory, The walking force).
    assert isinstance(SingleHarmonic(), ForceModel)
    assert isinstance(ZivanovicForce(), ForceModel) and isinstance(YoungForce(), ForceModel)


def test_user_force_response_psd_closed_form(paper_bridge, paper_crowd):
    # docs: theory, Response PSD with HSI, without an MSD and one mode: G_ü(f) = ω⁴ φ_o² |H(ω)|² Ψ₁₁ s(f),
    # H = 1/(m (ω₁² − ω² + 2i ξ ω₁ ω)), φ_o = 1 at midspan (unity-scaled beam), Ψ₁₁ = n/2 = 37.5.
    force = SingleHarmonic()
    frequency = np.linspace(0.5, 4.0, 351)
    psd = response_psd(paper_bridge, paper_crowd, frequency, force=force,
                       crowd_model="smeared").psd[0]
    omega, omega1 = 2 * np.pi * frequency, 2 * np.pi * 2.0
    receptance = 1 / (50e3 * (omega1**2 - omega**2 + 2j * 0.005 * omega1 * omega))
    weight = 70.0 * STANDARD_GRAVITY
    s = weight**2 * 0.4**2 / 2 * np.exp(-0.5 * ((frequency - 1.89) / 0.175) ** 2) / (
        0.175 * np.sqrt(2 * np.pi))
    expected = omega**4 * np.abs(receptance) ** 2 * 37.5 * s
    np.testing.assert_allclose(psd, expected, rtol=1e-6, atol=1e-12 * expected.max())


def test_user_force_simulation_matches_spectral(paper_bridge, paper_crowd):
    # docs: theory, Time domain against spectral model: the simulated modal load's Welch PSD against
    # Ψ₁₁ s(f). 600 s in 60 s windows (19 with overlap): the band variance of one realisation
    # scatters by about 1/√19 ≈ 23 % per Welch bin, less over the band 1.5–2.3 Hz (48 bins, but
    # one crowd realisation): seeds 7, 8, 9 gave 1.06, 0.89, 0.95, hence ±15 % for the seeded run.
    force = SingleHarmonic()
    record = simulate(paper_bridge, paper_crowd, 600.0, force=force, rng=7,
                      record_modal_load=True)
    from crowdvib import welch_psd
    load = welch_psd(record.modal_load, record.sample_rate, window_length=WINDOW)
    band = (load.frequency >= 1.5) & (load.frequency <= 2.3)
    measured = np.trapezoid(load.psd[0, band], load.frequency[band])
    model = np.trapezoid(37.5 * force.load_spectrum(load.frequency[band], paper_crowd),
                         load.frequency[band])
    assert measured / model == pytest.approx(1.0, abs=0.15)
    # and the acceleration's Welch PSD peaks in the resonant bin of the spectral one
    spectral = response_psd(paper_bridge, paper_crowd, GRID, force=force,
                            welch_window_length=WINDOW, crowd_model="smeared")
    assert abs(record.psd(WINDOW).peak_frequency()[0] - spectral.peak_frequency()[0]) \
        <= 1 / WINDOW + 1e-9


def test_user_force_estimate_recovers_msd(paper_bridge, paper_crowd, paper_msd):
    # A noise-free spectral PSD made with the user's force gives back its MSD (3.0 Hz, 0.30; docs:
    # theory, Estimating the MSD from a measured PSD): the estimator calls the same load_spectrum.
    force = SingleHarmonic()
    measured = response_psd(paper_bridge, paper_crowd, GRID, msd=paper_msd, force=force,
                            welch_window_length=WINDOW, crowd_model="smeared")
    # The PSD holds the smeared crowd: the paper's estimator fits that model exactly.
    estimate = estimate_hsi(measured, paper_bridge, paper_crowd, band=(1.0, 3.0), force=force,
                            interval=None, method="least_squares")
    assert estimate.msd.frequency == pytest.approx(3.0, rel=1e-3)
    assert estimate.msd.damping_ratio == pytest.approx(0.30, rel=1e-2)


def test_user_force_modal_load_psd_and_plot(paper_bridge, paper_crowd):
    # docs: theory, Modal load PSD of a Poisson crowd: G_QQ = Ψ s(f), Ψ₁₁ = 37.5; the load figure
    # draws it for a user's model too (it has no modal_load_psd method of its own).
    import matplotlib
    matplotlib.use("Agg")
    from crowdvib.models.loading import modal_load_psd
    from crowdvib.response.frequency_domain.plots import plot_load_psd

    force, frequency = SingleHarmonic(), np.array([1.5, 1.89, 2.2])
    psd = modal_load_psd(force, frequency, paper_crowd, paper_bridge)
    np.testing.assert_allclose(psd[:, 0, 0], 37.5 * force.load_spectrum(frequency, paper_crowd),
                               rtol=1e-12)
    ax = plot_load_psd(frequency, paper_crowd, structure=paper_bridge, force=force)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), psd[:, 0, 0], rtol=1e-12)


def test_force_lacking_members_is_refused(paper_bridge, paper_crowd):
    # The error names what the caller needs (issue 26 §3): load_spectrum for the spectral model.
    class NoSpectrum:
        ratios = np.array([1.0])

        def sample(self, step_frequency, rng):
            raise AssertionError("not reached")

    with pytest.raises(ParameterError, match="got NoSpectrum .*lacks load_spectrum"):
        response_psd(paper_bridge, paper_crowd, GRID, force=NoSpectrum())
    with pytest.raises(ParameterError, match="got NoSample .*lacks sample"):
        simulate(paper_bridge, paper_crowd, 10.0, force=type("NoSample", (), {"ratios": 1.0})())


# ------------------------------------------------------------------ the case file's force
def _case(tmp_path, force):
    """The beam case of test_casefile with ``force`` at the top level (before any table)."""
    path = write_case(tmp_path, name="beam.toml")
    path.write_text(f"{force}\n" + path.read_text())
    return load_case(path)


@pytest.mark.parametrize("value, kind", [("young", YoungForce), ("zivanovic", ZivanovicForce),
                                         ("measured", MeasuredForce)])
def test_case_chooses_the_force(tmp_path, value, kind):
    # docs/casefiles.rst, top level: force = "zivanovic" | "young" | "measured" (issue 26 §3).
    case = _case(tmp_path, f'force = "{value}"')
    assert type(case.force) is kind
    assert case.inputs()["force"] == kind.__name__
    assert "force" not in case.inputs()["not_set"]


def test_case_force_defaults_to_zivanovic(tmp_path):
    # Every command used Živanović before the key existed: the default keeps that (issue 26 §3).
    case = _case(tmp_path, "")
    assert case.force == ZivanovicForce()
    assert case.inputs()["not_set"]["force"] == "default"


@pytest.mark.parametrize("value, shown", [('"Young"', "'Young'"), ('"setra"', "'setra'"),
                                          ("1", "1")])
def test_case_bad_force_names_key_and_choices(tmp_path, value, shown):
    # docs/casefiles.rst: a bad value names the file, the key, the allowed values and the value.
    rule = ("must be one of \\['zivanovic', 'young', 'measured'\\]" if value != "1"
            else "must be a string")
    with pytest.raises(ParameterError, match=f"^beam.toml: force {rule}, got {shown}"):
        _case(tmp_path, f"force = {value}")


# ------------------------------------------------------------------ the formats table
def _writable(data):
    """(format name, file name) for every suffix of every format with a writer; a format known
    by name only (MATLAB v7.3 shares .mat with v5) under a file of its own."""
    return [(row.name, f"file{suffix}") for row in file_formats(data).values()
            if row.writer is not None for suffix in (row.suffixes or (f"_{row.name}.mat",))]


@pytest.mark.parametrize("name, filename", _writable("record"))
def test_every_record_format_round_trips(tmp_path, name, filename):
    # issue 26 §3: the table drives read_record/write_record; a format found by its suffix reads
    # back what was written (float64: exactly, apart from CSV's and UFF's 17-digit text).
    row = file_formats("record")[name]
    record = Record(np.random.default_rng(1).normal(size=(2, 300)), 100.0, ["deck", "pier"])
    path = write_record(record, tmp_path / filename, format=None if row.suffixes else name)
    back = read_record(path, format=None if row.suffixes else name)
    assert back.channel_names == ("deck", "pier") and back.sample_rate == pytest.approx(100.0)
    np.testing.assert_allclose(back.data, record.data, rtol=1e-12)


@pytest.mark.parametrize("name, filename", _writable("modes"))
def test_every_modal_format_round_trips(tmp_path, paper_bridge, name, filename):
    # docs/casefiles.rst, [structure] modal_table/mode_shapes/output_points: what the table's writer
    # writes, its reader reads back (issue 26 §3).
    row = file_formats("modes")[name]
    table, shapes, points = (tmp_path / f"{stem}{Path(filename).suffix}"
                             for stem in ("modes", "shapes", "points"))
    row.writer(paper_bridge, table, shapes, points)
    back = row.reader(table, shapes, width=paper_bridge.width, output_points=points)
    np.testing.assert_allclose(back.frequencies, paper_bridge.frequencies, rtol=1e-9)
    np.testing.assert_allclose(back.modal_masses, paper_bridge.modal_masses, rtol=1e-9)
    np.testing.assert_allclose(back.mode_shapes, paper_bridge.mode_shapes, rtol=1e-9, atol=1e-12)
    assert back.output_names == paper_bridge.output_names


def test_formats_table_drives_suffixes():
    # The table is the one place of suffixes: records, modal files and the CLI read it.
    assert RECORD_FORMATS == {n: row.suffixes for n, row in file_formats("record").items()}
    assert suffix_format("walk.UNV", "record").name == "uff"
    assert suffix_format("modes.unv", "modes").reader is read_fe_modes
    assert suffix_format("modes.xyz", "modes") is None
