"""Make the example cases' modal files and records with crowdvib itself.

Run from the repository root: ``python examples/make_examples.py [name ...]`` (names:
paper_example, eeklo_like, waalse_krook_like, ambient; default all). Every record is a time-domain
simulation (``crowdvib.simulate``) with the MSD model of the case's ``[expected]`` table and the
case's ``seed``, resampled to the case's ``simulation.record_sample_rate`` and stored as float32
NPZ to keep the files small. The case files themselves (``*.toml``) are written by hand; this
script reads them, so the records always match what the case files say. The ambient test of
``crowdvib modes`` (``ambient/``) is the empty bridge shaken by white-noise modal loads
(``crowdvib.oma.ambient_response``) with the modes of ``AMBIENT_*`` below.

The bridges are look-alikes of the paper's case studies (docs: theory, The paper's case studies): the real measurements
are not public. Values not printed in the paper are assumed and marked so in the case files.
"""

import sys
import time
from pathlib import Path

import numpy as np

import crowdvib
from crowdvib.io.casefile import load_case, write_modal_model
from crowdvib.io.records import Record, write_record
from crowdvib.signals import resample
from crowdvib.models.structure import ModalModel

HERE = Path(__file__).resolve().parent

# ------------------------------------------------------------------------------ Eeklo-like
EEKLO_SPANS = (27.0, 42.0, 27.0)            # the paper: three spans 27–42–27 m
EEKLO_WIDTH = 3.5                            # ASSUMED (not printed in the paper)
# Modes 1, 2, 5, 8 at 1.69, 2.97, 5.68, 6.42 Hz are printed in the paper; the other ten
# frequencies (14 modes up to 12 Hz) are ASSUMED, spread between them.
EEKLO_FREQUENCIES = (1.69, 2.97, 3.85, 4.60, 5.68, 5.95, 6.15, 6.42, 7.30, 8.20, 9.10, 10.10,
                     11.0, 11.9)
# Damping 0.2–0.6 % per the paper; the individual values are ASSUMED.
EEKLO_DAMPING = (0.004, 0.003, 0.005, 0.006, 0.0025, 0.004, 0.005, 0.003, 0.004, 0.005, 0.0035,
                 0.0045, 0.005, 0.006)
# Modal-mass ratios μ_m,j at 0.50 persons/m² [%] (paper, Table 1; docs: theory, The paper's case studies).
EEKLO_MASS_RATIOS = (0.7, 10.5, 2.7, 0.4, 11.2, 3.3, 2.4, 11.4, 2.4, 1.7, 13.0, 1.1, 2.2, 0.6)
EEKLO_BODY_MASS, EEKLO_DENSITY = 73.2, 0.5  # the paper


def continuous_beam_modes(spans, n_modes, n_elements=192):
    """Bending modes of a uniform continuous beam on simple supports (Hermite beam elements).

    Returns stations [m] (element nodes) and shapes scaled to 1 at their largest |value|. Only the
    shapes are used; the frequencies are the case's own.
    """
    length = sum(spans)
    x = np.linspace(0.0, length, n_elements + 1)
    h = x[1] - x[0]
    k_e = np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                    [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]]) / h**3
    m_e = h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                              [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    n_dof = 2 * x.size
    K, M = np.zeros((n_dof, n_dof)), np.zeros((n_dof, n_dof))
    for e in range(n_elements):
        index = np.arange(2 * e, 2 * e + 4)
        K[np.ix_(index, index)] += k_e
        M[np.ix_(index, index)] += m_e
    supports = np.cumsum((0.0,) + tuple(spans))
    fixed = [2 * int(np.argmin(np.abs(x - s))) for s in supports]
    free = np.setdiff1d(np.arange(n_dof), fixed)
    from scipy.linalg import eigh

    _, vectors = eigh(K[np.ix_(free, free)], M[np.ix_(free, free)], subset_by_index=(0, n_modes - 1))
    full = np.zeros((n_dof, n_modes))
    full[free] = vectors
    shapes = full[0::2]
    shapes /= shapes[np.argmax(np.abs(shapes), axis=0), np.arange(n_modes)]
    return x, shapes


def eeklo_structure():
    x, shapes = continuous_beam_modes(EEKLO_SPANS, len(EEKLO_FREQUENCIES))
    main_centre = EEKLO_SPANS[0] + EEKLO_SPANS[1] / 2
    side_centre = EEKLO_SPANS[0] / 2
    base = ModalModel(frequencies=EEKLO_FREQUENCIES, damping_ratios=EEKLO_DAMPING,
                      modal_masses=np.ones(len(EEKLO_FREQUENCIES)), positions=x,
                      mode_shapes=shapes, width=EEKLO_WIDTH, output_names=(),
                      output_shapes=np.zeros((0, len(EEKLO_FREQUENCIES))), name="Eeklo-like")
    # Modal masses such that μ_m,j = m_h Ψ_jj / m_j matches the paper's Table 1 at 0.5 p/m².
    psi = np.diag(base.influence_matrix(EEKLO_DENSITY))
    masses = EEKLO_BODY_MASS * psi / (np.array(EEKLO_MASS_RATIOS) / 100)
    outputs = base.shapes_at(np.array([main_centre, side_centre]))
    return base.replace(modal_masses=masses, output_names=("main_span", "side_span"),
                        output_shapes=outputs)


# ------------------------------------------------------------------------ Waalse-Krook-like
WK_LENGTH, WK_WIDTH = 25.0, 6.9                        # the paper
WK_FREQUENCIES, WK_DAMPING = (3.30, 4.14), (0.0086, 0.0025)   # the paper: bending, torsion
WK_MASS_RATIOS = (5.8, 5.7)                            # the paper μ_m [%] at 1.0 p/m²
WK_BODY_MASS, WK_DENSITY = 72.0, 1.0                   # the paper


def waalse_krook_structure():
    """Simply supported plate strip: a bending mode uniform across the width and a torsional
    mode varying linearly across it (ASSUMED shapes), seven lanes from edge to edge."""
    x = np.linspace(0.0, WK_LENGTH, 101)
    lanes = np.linspace(0.0, WK_WIDTH, 7)
    sine = np.sin(np.pi * x / WK_LENGTH)
    shapes = np.stack([np.stack([sine, sine * (2 * y / WK_WIDTH - 1)], axis=-1) for y in lanes])
    base = ModalModel(frequencies=WK_FREQUENCIES, damping_ratios=WK_DAMPING,
                      modal_masses=(1.0, 1.0), positions=x, mode_shapes=shapes, width=WK_WIDTH,
                      lanes=lanes, output_names=(), output_shapes=np.zeros((0, 2)),
                      name="Waalse-Krook-like")
    psi = np.diag(base.influence_matrix(WK_DENSITY))
    masses = WK_BODY_MASS * psi / (np.array(WK_MASS_RATIOS) / 100)
    # Outputs at the antinodes: midspan centreline (bending) and midspan edge (torsion).
    return base.replace(modal_masses=masses, output_names=("bending_antinode", "torsion_antinode"),
                        output_shapes=[[1.0, 0.0], [1.0, 1.0]])


def make_record(case_path, record_path):
    """Simulate the case's crowd with its [expected] MSD and write the float32 record."""
    case = load_case(case_path)
    msd = crowdvib.MSDModel(case.expected["frequency"], case.expected["damping_ratio"],
                            case.expected.get("mass_ratio", 0.95))
    spec = case.simulation
    started = time.perf_counter()
    simulation = crowdvib.simulate(case.structure, case.crowd, spec.duration, msd=msd,
                                   sample_rate=spec.sample_rate, rng=case.seed,
                                   warm_up=spec.warm_up)
    data, rate = simulation.acceleration, spec.sample_rate
    if spec.record_sample_rate:
        data, rate = resample(data, rate, spec.record_sample_rate)
    record = Record(data=data, sample_rate=rate, channel_names=simulation.output_names)
    write_record(record, record_path, dtype="float32")
    print(f"{record_path.name}: {record.n_channels} × {record.n_samples} samples at {rate:g} Hz, "
          f"seed {simulation.seed}, {time.perf_counter() - started:.0f} s")


# ------------------------------------------------------------------------------ ambient test
# The paper example's 50 m × 3 m beam with its first two bending modes (f_j = j² f_1 would put the
# second at 8 Hz; 7.5 Hz and 0.8 % are ASSUMED, a stiffer deck than the Euler–Bernoulli beam),
# seen by three accelerometers; 30 min of ambient response at 20 Hz, float32.
AMBIENT_FREQUENCIES = (2.0, 7.5)            # [Hz]
AMBIENT_DAMPING = (0.005, 0.008)            # [-]
AMBIENT_MODAL_MASS = 50e3                   # [kg], unity-scaled sine modes
AMBIENT_SENSORS = {"quarter": 12.5, "mid": 25.0, "three_quarter": 37.5}   # [m]
AMBIENT_DURATION, AMBIENT_SAMPLE_RATE, AMBIENT_LOAD_PSD, AMBIENT_SEED = 1800.0, 20.0, 200.0**2, 27


def make_ambient(record_path):
    """The ambient record of ``ambient/paper_beam_ambient.toml`` (white-noise modal loads)."""
    from crowdvib.oma.identify import ambient_response

    beam = ModalModel.simply_supported_beam(50.0, 3.0, AMBIENT_FREQUENCIES, AMBIENT_DAMPING,
                                            AMBIENT_MODAL_MASS, n_modes=2,
                                            outputs=AMBIENT_SENSORS)
    data = ambient_response(beam, AMBIENT_DURATION, AMBIENT_SAMPLE_RATE, AMBIENT_LOAD_PSD,
                            rng=AMBIENT_SEED)
    record = Record(data=data, sample_rate=AMBIENT_SAMPLE_RATE,
                    channel_names=list(AMBIENT_SENSORS))
    write_record(record, record_path, dtype="float32")
    print(f"{record_path.name}: {record.n_channels} × {record.n_samples} samples at "
          f"{AMBIENT_SAMPLE_RATE:g} Hz, seed {AMBIENT_SEED}")


def main(names):
    if "eeklo_like" in names:
        write_modal_model(eeklo_structure(), HERE / "eeklo_like_modes.csv",
                          HERE / "eeklo_like_shapes.csv", HERE / "eeklo_like_outputs.csv")
        make_record(HERE / "eeklo_like.toml", HERE / "eeklo_like_record.npz")
    if "waalse_krook_like" in names:
        write_modal_model(waalse_krook_structure(), HERE / "waalse_krook_like_modes.csv",
                          HERE / "waalse_krook_like_shapes.csv",
                          HERE / "waalse_krook_like_outputs.csv")
        make_record(HERE / "waalse_krook_like.toml", HERE / "waalse_krook_like_record.npz")
    if "paper_example" in names:
        make_record(HERE / "paper_example.toml", HERE / "paper_example_record.npz")
    if "ambient" in names:
        make_ambient(HERE / "ambient" / "paper_beam_ambient_record.npz")


if __name__ == "__main__":
    main(sys.argv[1:] or ["paper_example", "eeklo_like", "waalse_krook_like", "ambient"])
