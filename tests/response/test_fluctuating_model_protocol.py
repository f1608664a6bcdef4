"""The spectral models share one protocol (issue 34 §4): the smeared crowd's, the fluctuating
crowd's and the varying crowd's expected PSD are used through ``ExpectedPSDModel`` alone, with
no ``hasattr`` dispatch (docs: theory, The fluctuating crowd; A crowd that changes)."""

import numpy as np

from crowdvib import CrowdProfile
from crowdvib.response import (ExpectedPSDModel, FluctuatingSpectralModel, SpectralModel,
                               VaryingCrowdModel)


def test_every_spectral_model_is_an_expected_psd_model_and_changes_its_step_frequencies(
        paper_bridge, paper_crowd, paper_msd):
    grid = np.arange(60, 480) / 60.0
    other = paper_crowd.__class__(**{**paper_crowd.to_dict(), "step_frequency_mean": 1.95})
    profile = CrowdProfile.from_counts([0.0, 600.0], [40, 80], paper_bridge.area)
    models = [SpectralModel(paper_bridge, paper_crowd, grid),
              FluctuatingSpectralModel(paper_bridge, paper_crowd, grid),
              VaryingCrowdModel(paper_bridge, paper_crowd.with_density(profile), grid,
                                duration=1200.0)]
    for model in models:
        assert isinstance(model, ExpectedPSDModel)
        assert isinstance(model.details(), dict)
        changed = model.with_step_frequencies(other.with_density(model.crowd.density))
        assert type(changed) is type(model)
        assert changed.crowd.step_frequency_mean == 1.95
        # the psd of the model is its psd_array, as a ResponsePSD
        assert np.array_equal(model.psd(paper_msd).psd, model.psd_array(paper_msd))
    # The smeared model with other step frequencies is the model built for that crowd.
    rebuilt = SpectralModel(paper_bridge, other, grid).psd_array(paper_msd)
    np.testing.assert_allclose(models[0].with_step_frequencies(other).psd_array(paper_msd),
                               rebuilt, rtol=1e-12)
