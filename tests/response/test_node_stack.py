"""The occupancy nodes of a mixture computed as one stack of crowds at a new MSD
(spectral._pole_terms, response.frequency_domain._poles; issues 33 §5 and 39) against each node
computed alone, including a nearly defective node that falls back to the dense rule alone."""

import numpy as np
import pytest

from crowdvib import Crowd, MSDModel, ModalModel, SpectralModel, TunedMassDamper
from crowdvib.response.frequency_domain import _poles
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel, _mixture
from crowdvib.response.frequency_domain.spectral import _pole_terms, expected_psds

FREQUENCY = np.arange(60, 241) / 60.0
WINDOW = 60.0
BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
# Near an exceptional point of this bridge's mode and the MSD (their two poles meet): found by
# Newton's method on (λ₁ − λ₂)² in (density, f_h1) at ξ_h1 = 0.1, which stalls at |λ₁ − λ₂|
# ≈ 3e-7 |λ| (rounding); there the expansion misses the direct solve by ~4e-10 (relative),
# against ~1e-15 at the other densities.
NEAR_DEFECTIVE_DENSITY, NEAR_DEFECTIVE_MSD = 0.09143627161688218, MSDModel(1.9805149508898325, 0.1)


def _nodes(structure, densities, dampers=None):
    """The nodes as a mixture builds them: one model's copies for other densities."""
    base = SpectralModel(structure, Crowd.from_density(0.5), FREQUENCY, welch_window_length=WINDOW,
                         dampers=dampers)
    return [base._for_crowd(base.crowd.with_density(d)) for d in densities]


def _alone(model, msd, cross):
    """Reference: the per-node computation every node took before the stack (as
    SpectralModel._expected did it): _pole_residue on this crowd's B alone, its check, then the
    Welch rule's terms; () where the dense rule is used."""
    expansion = _poles._pole_residue(model.structure, model._attached(msd), model._load_factor,
                                     model._shapes, model._probe)
    if expansion is None or not expansion[3] or not np.all(expansion[0].real < 0):
        return ()
    poles, left, right, _ = expansion
    welch = model._welch
    return (poles,) + (welch.cross_terms if cross else welch.power_terms)(poles, left, right) + (
        welch.pole_parts(poles),)


def _assert_same_terms(stacked, alone):
    assert len(stacked) == len(alone)
    for got, expected in zip(stacked, alone):
        assert bool(got) == bool(expected)
        for got_part, expected_part in zip(got[:3], expected[:3]):
            np.testing.assert_allclose(got_part, expected_part, rtol=1e-12,
                                       atol=1e-12 * np.abs(expected_part).max())


TWO_MODES = ModalModel.simply_supported_beam(50.0, 3.0, [2.0, 7.5], [0.005, 0.01],
                                             [50e3, 60e3], n_modes=2)


@pytest.mark.parametrize("structure, dampers", [
    (BRIDGE, None),
    # two modes and a damper: the compiled solve of the check and a part without a stack
    (TWO_MODES, [TunedMassDamper(mass=500.0, frequency=1.95, damping_ratio=0.08,
                                 position=25.0)])], ids=["one mode", "two modes, damper"])
@pytest.mark.parametrize("cross", [False, True])
def test_stacked_nodes_equal_each_node_alone(structure, dampers, cross):
    msd = MSDModel(3.1, 0.3)
    densities = (0.2, 0.5, 1.1)
    stacked = _pole_terms(_nodes(structure, densities, dampers), msd, cross)
    alone = [_alone(model, msd, cross) for model in _nodes(structure, densities, dampers)]
    assert all(alone)
    _assert_same_terms(stacked, alone)


def test_a_nearly_defective_node_falls_back_to_the_dense_rule_alone(monkeypatch):
    # At the stated tolerance (1e-7) the node would have to lie nearer the exceptional point
    # than rounding lets Newton's method reach: the tolerance is tightened to 1e-12, between the
    # near-defective node's mismatch (~4e-10) and the others' (~1e-15).
    monkeypatch.setattr(_poles, "_MODAL_CHECK_TOLERANCE", 1e-12)
    densities = (0.5, NEAR_DEFECTIVE_DENSITY, 1.1)
    msd = NEAR_DEFECTIVE_MSD
    models = _nodes(BRIDGE, densities)
    stacked = _pole_terms(models, msd, False)
    alone = [_alone(model, msd, False) for model in _nodes(BRIDGE, densities)]
    assert [bool(terms) for terms in alone] == [True, False, True]
    _assert_same_terms(stacked, alone)
    # Reference for the fallen-back node: the dense rule (SpectralModel._dense_welch_psd).
    psds = expected_psds(models, msd)
    np.testing.assert_array_equal(psds[1], models[1]._dense_welch_psd(models[1]._attached(msd)))
    for model, psd in zip(models[::2], psds[::2]):
        np.testing.assert_array_equal(psd, model._welch.psd_from(*stacked[models.index(model)]))


def test_a_singular_stack_is_computed_node_by_node(monkeypatch):
    # A stack whose eigenvector matrix is singular (LinAlgError, here forced for every stack of
    # more than one crowd) is computed node by node; reference: each node alone (_alone).
    decomposition = _poles.eigen_decomposition

    def refusing_stacks(state, *args, **kwargs):
        if state.ndim == 3 and state.shape[0] > 1:
            raise np.linalg.LinAlgError("singular")
        return decomposition(state, *args, **kwargs)

    monkeypatch.setattr(_poles, "eigen_decomposition", refusing_stacks)
    msd, densities = MSDModel(2.6, 0.4), (0.2, 0.5, 1.1)
    stacked = _pole_terms(_nodes(BRIDGE, densities), msd, False)
    alone = [_alone(model, msd, False) for model in _nodes(BRIDGE, densities)]
    assert all(alone)
    _assert_same_terms(stacked, alone)


@pytest.mark.parametrize("cross", [False, True])
def test_mixture_of_stacked_nodes_equals_the_sum_of_the_nodes_alone(cross):
    # Reference: Σ_i w_i G_i with each node's PSD from a fresh model of its own (no stack, no
    # shared memory), the definition of the quasi-static mixture.
    crowd = Crowd.from_density(0.5)
    mixture = FluctuatingSpectralModel(BRIDGE, crowd, FREQUENCY, welch_window_length=WINDOW)
    msd = MSDModel(2.8, 0.35)
    got = mixture.cross_psd_array(msd) if cross else mixture.psd_array(msd)
    expected = sum(
        weight * (lambda node: node.cross_psd_array(msd) if cross else node.psd_array(msd))(
            SpectralModel(BRIDGE, model.crowd, FREQUENCY, welch_window_length=WINDOW,
                          crossing_spread=mixture.crossing_spread))
        for weight, model in zip(mixture.weights, mixture._models))
    expected = expected + mixture._modulation(msd, cross)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_allclose(_mixture(mixture.weights, mixture._models, msd, cross),
                               got - mixture._modulation(msd, cross), rtol=1e-12,
                               atol=1e-12 * np.abs(expected).max())
