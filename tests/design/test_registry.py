"""Design codes as peers (issue 26 §3): a code defined outside the package, registered, and used
end to end through design_check."""

import numpy as np
import pytest

from crowdvib import ModalModel, MSDModel, ParameterError
from crowdvib.design import (DesignCheck, DesignCode, code_names, design_check, register_code,
                             unregister_code)
from crowdvib.design.check import structure_models
from crowdvib.models.crowd import Crowd
from crowdvib.response.frequency_domain.spectral import effective_modal_properties

FORCE = 280.0                                            # N, one walker's first harmonic


class OneWalkerCode(DesignCode):
    """A toy code: one walker's 280 N at the antinode of each mode, resonant, a = F φ_max/(2ξm)
    at the antinode, on every model of the structure."""

    name = "one_walker"
    options = frozenset({"comfort_class"})

    def check(self, structure, *, traffic_class, density, crowd, msd, dampers,
              comfort_class=None):
        limit = {None: 1.0, "strict": 0.5}[comfort_class]
        crowd = Crowd.from_density(1.0) if crowd is None else crowd
        models = structure_models(structure, crowd, 0.0 if density is None else density, msd)
        props = [effective_modal_properties(*model, dampers=dampers) for model in models.values()]
        peak_shape = np.abs(structure.mode_shapes).max(axis=(0, 1))
        forces = np.array([FORCE * peak_shape for _ in props])
        peaks = np.array([np.abs(structure.output_shapes) * force / (2 * p.damping_ratios
                                                                    * p.modal_masses)
                          for force, p in zip(forces, props)])
        return DesignCheck(
            code=self.name, traffic_class=traffic_class, density=0.0, limit=limit,
            output_names=structure.output_names, models=tuple(models),
            frequencies=[p.frequencies for p in props],
            damping_ratios=[p.damping_ratios for p in props],
            modal_masses=[p.modal_masses for p in props], modal_forces=forces,
            harmonics=np.ones(forces.shape, int), peak_accelerations=peaks)


@pytest.fixture
def one_walker():
    code = register_code(OneWalkerCode())
    yield code
    unregister_code(code.name)


def test_a_code_defined_outside_the_package_runs_through_design_check(one_walker, paper_bridge):
    assert code_names()[-1] == "one_walker"
    check = design_check(paper_bridge, "one_walker", density=0.5, msd=MSDModel(3.0, 0.3, 0.95))
    # Closed form on the empty model: 280 N / (2 × 0.005 × 50 t) = 0.56 m/s² at midspan of the
    # unity-scaled sine mode (docs: theory, The paper's numerical example).
    assert check.governing_of("empty")[0] == pytest.approx(FORCE / (2 * 0.005 * 50e3), rel=1e-9)
    assert check.models == ("empty", "added_mass", "hsi") and check.primary == "hsi"
    # 0.5 P/m² of MSDs: the occupied mode (ξ 1.2 %, 55 t) takes it below half.
    assert check.governing[0] < 0.5 * check.governing_of("empty")[0]
    assert design_check(paper_bridge, "one_walker", comfort_class="strict").limit == 0.5
    # The shared inputs are validated before the code runs, and options it does not take are
    # refused by design_check, not silently ignored.
    with pytest.raises(ParameterError, match=r"site_factors does not apply to code "
                                             r"'one_walker' \(it takes \['comfort_class'\]\)"):
        design_check(paper_bridge, "one_walker", site_factors=(1, 1, 1, 1))
    with pytest.raises(ParameterError, match="msd must be an MSDModel"):
        design_check(paper_bridge, "one_walker", msd="3 Hz")


def test_registry_refuses_bad_codes(one_walker):
    with pytest.raises(ParameterError, match="'one_walker' is already registered"):
        register_code(OneWalkerCode())
    assert register_code(OneWalkerCode(), replace=True).name == "one_walker"
    with pytest.raises(ParameterError, match="code must be a DesignCode instance, got str"):
        register_code("one_walker")

    class Misnamed(OneWalkerCode):
        name = ""

    with pytest.raises(ParameterError, match="name must be a non-empty str, got ''"):
        register_code(Misnamed())

    class Greedy(OneWalkerCode):
        name = "greedy"
        options = frozenset({"wind_speed"})

    with pytest.raises(ParameterError, match=r"options must be among .* got \['wind_speed'\]"):
        register_code(Greedy())
    with pytest.raises(ParameterError, match=r"code must be one of \['setra', 'hivoss', "
                                             r"'en1990', 'ukna', 'one_walker'\], got 'greedy'"):
        design_check(ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3), "greedy")


def test_codes_are_named_in_words(one_walker):
    # Reports and verdicts write a code's label (the built-ins as their documents name
    # themselves), a plug-in's name when it has no label, and the name of a code no longer
    # registered (a results file read back).
    from crowdvib.design import code_label

    assert [code_label(name) for name in ("setra", "hivoss", "en1990", "ukna")] == [
        "Sétra", "HiVoSS", "EN 1990", "UK NA"]
    assert code_label("one_walker") == "one_walker"
    assert code_label("retired") == "retired"
