"""The estimate as a sequence of pure steps (issue 26 §4): same numbers, immutable objective.

The reference values were recorded on commit 89c377c (before the estimate was split into
steps) by running this module's ``_run`` on the untouched code; the steps must reproduce them
to round-off (1e-12 relative) with the numpy and scipy of the recording, for every main option
combination.
"""

import warnings

import numpy as np
import pytest
import scipy

from crowdvib import (Crowd, ModalModel, MSDModel, estimate_hsi, estimate_hsi_joint, response_psd,
                      welch_psd)
from crowdvib.identification import PSDObjective
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

# The paper's numerical example (docs: theory, The paper's numerical example), a 20-min record.
BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
CROWD = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
              step_frequency_std=0.175, body_mass=70.0)
TRUTH = MSDModel(3.0, 0.30, 0.95)

#: method/crowd_model/free_step_frequencies/interval → the estimate on commit 89c377c.
RECORDED = {
    'least_squares/smeared/False/profile': {'theta': [3.0254495300640127, 0.3622902940480018], 'cost': 0.002151512576069092, 'cost_no_hsi': 16.524130861827047, 'n_evaluations': 18, 'level_ratio': [0.9884835452545583], 'covariance': [0.007438311603046399, 0.00034181210511067384, 0.000341812105110677, 0.0053109430886166525], 'intervals': {'frequency': [2.8580653651498102, 3.1997871755065694], 'damping_ratio': [0.25052170500717325, 0.5460444035745747]}},
    'least_squares/smeared/False/wald': {'theta': [3.0254495300640127, 0.3622902940480018], 'cost': 0.002151512576069092, 'cost_no_hsi': 16.524130861827047, 'n_evaluations': 18, 'level_ratio': [0.9884835452545583], 'covariance': [0.007438311603046399, 0.00034181210511067384, 0.000341812105110677, 0.0053109430886166525], 'intervals': {}},
    'least_squares/smeared/True/profile': {'theta': [3.078168626904417, 0.392465730408233, 1.8362111084847503, 0.15671089197652419], 'cost': 0.0011677348073408525, 'cost_no_hsi': 10.317819590728616, 'n_evaluations': 45, 'level_ratio': [1.014361333805123], 'covariance': [0.03790744697343308, -0.004637824331247092, -0.004990987256545323, 0.0030338522674278555, -0.004637824331246938, 0.013733565887410143, -0.0014339966274546975, -0.003352519701196734, -0.00499098725654546, -0.001433996627454617, 0.0013627077969023751, 0.0002264961715149511, 0.003033852267427704, -0.0033525197011966814, 0.0002264961715149913, 0.0013302143634840863], 'intervals': {'frequency': [2.6058210995733626, 3.571864913817067], 'damping_ratio': [0.21355103845032314, 0.804445015143346], 'step_frequency_mean': [1.7867031596295675, 1.992507548288583], 'step_frequency_std': [0.09962186767232518, 0.23348063217874135]}},
    'least_squares/smeared/True/wald': {'theta': [3.078168626904417, 0.392465730408233, 1.8362111084847503, 0.15671089197652419], 'cost': 0.0011677348073408525, 'cost_no_hsi': 10.317819590728616, 'n_evaluations': 45, 'level_ratio': [1.014361333805123], 'covariance': [0.03790744697343308, -0.004637824331247092, -0.004990987256545323, 0.0030338522674278555, -0.004637824331246938, 0.013733565887410143, -0.0014339966274546975, -0.003352519701196734, -0.00499098725654546, -0.001433996627454617, 0.0013627077969023751, 0.0002264961715149511, 0.003033852267427704, -0.0033525197011966814, 0.0002264961715149913, 0.0013302143634840863], 'intervals': {}},
    'least_squares/fluctuating/False/profile': {'theta': [3.049984544650563, 0.34255930087414826], 'cost': 0.003657908347404456, 'cost_no_hsi': 16.433885094790686, 'n_evaluations': 21, 'level_ratio': [0.9679647205692266], 'covariance': [0.00770068069767157, 0.0011906145384905755, 0.0011906145384905716, 0.005386430892503224], 'intervals': {'frequency': [2.8828483616565146, 3.2262464526816146], 'damping_ratio': [0.23305798870818814, 0.5244201447394203]}},
    'least_squares/fluctuating/False/wald': {'theta': [3.049984544650563, 0.34255930087414826], 'cost': 0.003657908347404456, 'cost_no_hsi': 16.433885094790686, 'n_evaluations': 21, 'level_ratio': [0.9679647205692266], 'covariance': [0.00770068069767157, 0.0011906145384905755, 0.0011906145384905716, 0.005386430892503224], 'intervals': {}},
    'least_squares/fluctuating/True/profile': {'theta': [3.2126191052411444, 0.3293421281862346, 1.8242541706822002, 0.18545878531845272], 'cost': 0.0011242421827455532, 'cost_no_hsi': 8.995614455928333, 'n_evaluations': 45, 'level_ratio': [1.0188903615746383], 'covariance': [0.041490035208832154, -0.0016393833346602848, -0.007878755829930226, 0.0020330033680670658, -0.0016393833346602532, 0.01478007407819385, -0.00214925972534974, -0.00524281133790821, -0.007878755829929987, -0.0021492597253496937, 0.0026632229445252968, 0.0008896185009091848, 0.0020330033680671933, -0.005242811337908198, 0.0008896185009091637, 0.0026217445638760726], 'intervals': {'frequency': [2.788930801657829, 3.863772137870912], 'damping_ratio': [0.1426736877633783, 0.7643634503233355], 'step_frequency_mean': [1.763349884926451, 2.033514796617916], 'step_frequency_std': [0.10868339303229628, 0.28205573770211406]}},
    'least_squares/fluctuating/True/wald': {'theta': [3.2126191052411444, 0.3293421281862346, 1.8242541706822002, 0.18545878531845272], 'cost': 0.0011242421827455532, 'cost_no_hsi': 8.995614455928333, 'n_evaluations': 45, 'level_ratio': [1.0188903615746383], 'covariance': [0.041490035208832154, -0.0016393833346602848, -0.007878755829930226, 0.0020330033680670658, -0.0016393833346602532, 0.01478007407819385, -0.00214925972534974, -0.00524281133790821, -0.007878755829929987, -0.0021492597253496937, 0.0026632229445252968, 0.0008896185009091848, 0.0020330033680671933, -0.005242811337908198, 0.0008896185009091637, 0.0026217445638760726], 'intervals': {}},
    'likelihood/smeared/False/profile': {'theta': [2.994924234223415, 0.31820315281334804], 'cost': 28.541560625591266, 'cost_no_hsi': 2681.6171370745747, 'n_evaluations': 18, 'level_ratio': [0.9964674110224804], 'covariance': [0.005128357137200515, -0.00031388615238357845, -0.00031388615238358067, 0.0020079099622690617], 'intervals': {'frequency': [2.863307020849173, 3.1473091940661018], 'damping_ratio': [0.2349506626087456, 0.4158443351622249]}},
    'likelihood/smeared/False/wald': {'theta': [2.994924234223415, 0.31820315281334804], 'cost': 28.541560625591266, 'cost_no_hsi': 2681.6171370745747, 'n_evaluations': 18, 'level_ratio': [0.9964674110224804], 'covariance': [0.005128357137200515, -0.00031388615238357845, -0.00031388615238358067, 0.0020079099622690617], 'intervals': {}},
    'likelihood/smeared/True/profile': {'theta': [2.9922421376661363, 0.33186492367623105, 1.888892264946516, 0.17372928229298168], 'cost': 27.958863023705675, 'cost_no_hsi': 2642.4003351427536, 'n_evaluations': 30, 'level_ratio': [1.0020638550305674], 'covariance': [0.006700394442731247, -0.00019607100440233004, -0.0002815792354784265, 0.0001650604532645904, -0.00019607100440215686, 0.0030106305676116303, -0.00013592103344042721, -4.016350218895161e-05, -0.0002815792354784341, -0.00013592103344040813, 7.003167050321142e-05, -2.8094319977698105e-05, 0.00016506045326458607, -4.0163502188958734e-05, -2.8094319977697522e-05, 2.612932798951442e-05], 'intervals': {'frequency': [2.8453237898899117, 3.1702299881569442], 'damping_ratio': [0.23402556697518495, 0.45451649691162954], 'step_frequency_mean': [1.8713422446821868, 1.903709525436812], 'step_frequency_std': [0.1649388212193922, 0.18481186705514266]}},
    'likelihood/smeared/True/wald': {'theta': [2.9922421376661363, 0.33186492367623105, 1.888892264946516, 0.17372928229298168], 'cost': 27.958863023705675, 'cost_no_hsi': 2642.4003351427536, 'n_evaluations': 30, 'level_ratio': [1.0020638550305674], 'covariance': [0.006700394442731247, -0.00019607100440233004, -0.0002815792354784265, 0.0001650604532645904, -0.00019607100440215686, 0.0030106305676116303, -0.00013592103344042721, -4.016350218895161e-05, -0.0002815792354784341, -0.00013592103344040813, 7.003167050321142e-05, -2.8094319977698105e-05, 0.00016506045326458607, -4.0163502188958734e-05, -2.8094319977697522e-05, 2.612932798951442e-05], 'intervals': {}},
    'likelihood/fluctuating/False/profile': {'theta': [3.0033017087833156, 0.3196360104432811], 'cost': 29.90444020002061, 'cost_no_hsi': 2688.7487698796012, 'n_evaluations': 18, 'level_ratio': [0.9983637591181869], 'covariance': [0.005183703009158429, -0.0001848173318232387, -0.00018481733182323785, 0.002080115344392167], 'intervals': {'frequency': [2.8715303098068183, 3.157829870411525], 'damping_ratio': [0.2355436913693984, 0.42100991848734054]}},
    'likelihood/fluctuating/False/wald': {'theta': [3.0033017087833156, 0.3196360104432811], 'cost': 29.90444020002061, 'cost_no_hsi': 2688.7487698796012, 'n_evaluations': 18, 'level_ratio': [0.9983637591181869], 'covariance': [0.005183703009158429, -0.0001848173318232387, -0.00018481733182323785, 0.002080115344392167], 'intervals': {}},
    'likelihood/fluctuating/True/profile': {'theta': [3.000350804607864, 0.3323470245538677, 1.889236795399554, 0.1736686594100852], 'cost': 29.419767075918685, 'cost_no_hsi': 2652.1108674784564, 'n_evaluations': 30, 'level_ratio': [1.0029517459088209], 'covariance': [0.006946306378248537, 3.7741767489688295e-05, -0.0003163307120509684, 0.00017894161651520714, 3.774176748978396e-05, 0.003180482477658532, -0.00015055531662803545, -4.031823098687986e-05, -0.0003163307120509706, -0.00015055531662803138, 7.324674980688957e-05, -2.9497618214487664e-05, 0.00017894161651520418, -4.031823098688096e-05, -2.949761821448755e-05, 2.7344559304803143e-05], 'intervals': {'frequency': [2.85189601842783, 3.1859221300468326], 'damping_ratio': [0.23246452435724832, 0.4619329427714261], 'step_frequency_mean': [1.8706795337525086, 1.904658261474562], 'step_frequency_std': [0.16452577501528481, 0.18541680769650565]}},
    'likelihood/fluctuating/True/wald': {'theta': [3.000350804607864, 0.3323470245538677, 1.889236795399554, 0.1736686594100852], 'cost': 29.419767075918685, 'cost_no_hsi': 2652.1108674784564, 'n_evaluations': 30, 'level_ratio': [1.0029517459088209], 'covariance': [0.006946306378248537, 3.7741767489688295e-05, -0.0003163307120509684, 0.00017894161651520714, 3.774176748978396e-05, 0.003180482477658532, -0.00015055531662803545, -4.031823098687986e-05, -0.0003163307120509706, -0.00015055531662803138, 7.324674980688957e-05, -2.9497618214487664e-05, 0.00017894161651520418, -4.031823098688096e-05, -2.949761821448755e-05, 2.7344559304803143e-05], 'intervals': {}},
    'least_squares/smeared/True/bootstrap': {'theta': [3.078168626904417, 0.392465730408233, 1.8362111084847503, 0.15671089197652419], 'cost': 0.0011677348073408525, 'cost_no_hsi': 10.317819590728616, 'n_evaluations': 45, 'level_ratio': [1.014361333805123], 'covariance': [0.03790744697343308, -0.004637824331247092, -0.004990987256545323, 0.0030338522674278555, -0.004637824331246938, 0.013733565887410143, -0.0014339966274546975, -0.003352519701196734, -0.00499098725654546, -0.001433996627454617, 0.0013627077969023751, 0.0002264961715149511, 0.003033852267427704, -0.0033525197011966814, 0.0002264961715149913, 0.0013302143634840863], 'intervals': {'frequency': [2.8467363570471034, 3.4891833377818475], 'damping_ratio': [0.17915090331672393, 0.5086760662905424], 'step_frequency_mean': [1.7851777600402017, 1.9390996533602087], 'step_frequency_std': [0.10634277995538721, 0.2158131905480919]}},
    'likelihood/smeared/True/bootstrap': {'theta': [2.9922421376661363, 0.33186492367623105, 1.888892264946516, 0.17372928229298168], 'cost': 27.958863023705675, 'cost_no_hsi': 2642.4003351427536, 'n_evaluations': 30, 'level_ratio': [1.0020638550305674], 'covariance': [0.006700394442731247, -0.00019607100440233004, -0.0002815792354784265, 0.0001650604532645904, -0.00019607100440215686, 0.0030106305676116303, -0.00013592103344042721, -4.016350218895161e-05, -0.0002815792354784341, -0.00013592103344040813, 7.003167050321142e-05, -2.8094319977698105e-05, 0.00016506045326458607, -4.0163502188958734e-05, -2.8094319977697522e-05, 2.612932798951442e-05], 'intervals': {'frequency': [2.8109335692248107, 3.0911458071006166], 'damping_ratio': [0.25374226028230057, 0.4049654310683131], 'step_frequency_mean': [1.87025846493772, 1.9035479506414026], 'step_frequency_std': [0.16466479675512957, 0.18016626223216756]}},
}


@pytest.fixture(scope="module")
def measured():
    frequency = record_frequencies(1200.0, 20.0)
    psd = response_psd(BRIDGE, CROWD, frequency, msd=TRUTH, crowd_model="smeared").psd
    record = gaussian_record(psd, 20.0, rng=7)
    return welch_psd(record, 20.0, window_length=60.0, output_names=["midspan"]).band(0.0, 10.0)


def _run(measured, key):
    method, crowd_model, free, interval = key.split("/")
    options = dict(n_boot=20, rng=3) if interval == "bootstrap" else {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # bound and identifiability notes: not the subject
        # The recorded covariances are the record's own scatter: the density taken as exact
        # (its stated uncertainty, a later addition, is tested in test_density_uncertainty).
        return estimate_hsi(measured, BRIDGE, CROWD, band=(0.0, 10.0), method=method,
                            crowd_model=crowd_model, free_step_frequencies=free == "True",
                            interval=interval, starts=[(2.5, 0.4)], density_uncertainty=0.0,
                            **options)


#: numpy and scipy of the recording. With other releases (Python 3.13 gets numpy 2.5 and scipy
#: 1.18, where 3.11 gets 2.4 and 1.17) the same code takes another rounding path through the
#: optimiser: estimates moved by up to 3.3e-7 relative (seen in CI on 3.13), so there the
#: numbers are held to 1e-5 and the evaluation count, which follows the path, is not compared.
RECORDED_WITH = ("2.4.6", "1.17.1")
SAME_LIBRARIES = (np.__version__, scipy.__version__) == RECORDED_WITH
TOLERANCE = 1e-8 if SAME_LIBRARIES else 1e-5


#: The likelihood with free step frequencies refits from the first fit's optimum since
#: issue 25 (one start instead of the given ones: its speed target): the optimiser then stops
#: elsewhere within its tolerance, 7.5e-7 relative at most on these rows (measured), so they
#: are held to 2e-6 and their evaluation count (first fit + refit) is not compared.
REFIT_FROM_OPTIMUM = 2e-6


#: Issue 39 reordered the fluctuating model's arithmetic (the parent's pole terms kept for other
#: step frequencies, the occupancy law computed once, the low-pass gain in closed form): the
#: optimiser then stops elsewhere within its tolerance, 1.6e-6 relative at most on these rows
#: (measured), and the covariance's finite differences move by 1.1e-7; those rows are held to
#: 2e-6 and their evaluation count is not compared.
REORDERED = 2e-6


def _close(actual, expected, tolerance=TOLERANCE):
    # Round-off of a changed operation order only: ``tolerance`` of the largest entry.
    expected = np.asarray(expected, dtype=float)
    np.testing.assert_allclose(actual, expected, rtol=tolerance,
                               atol=tolerance * np.max(np.abs(expected), initial=0.0))


@pytest.mark.parametrize("key", [pytest.param(k, marks=pytest.mark.slow)
                                 if "fluctuating/True/profile" in k else k for k in RECORDED])
def test_estimate_reproduces_the_recorded_numbers(measured, key):
    # Reference: the same call on commit 89c377c (RECORDED).
    expected, estimate = RECORDED[key], _run(measured, key)
    refit = key.startswith("likelihood") and "/True/" in key
    reordered = "/fluctuating/" in key
    tolerance = max(TOLERANCE, REFIT_FROM_OPTIMUM if refit else 0.0,
                    REORDERED if reordered else 0.0)
    theta = [estimate.msd.frequency, estimate.msd.damping_ratio]
    if estimate.crowd is not None:
        theta += [estimate.crowd.step_frequency_mean, estimate.crowd.step_frequency_std]
    _close(theta, expected["theta"], tolerance)
    _close([estimate.cost, estimate.cost_no_hsi], [expected["cost"], expected["cost_no_hsi"]],
           tolerance)
    # Since issue 39 a fit ends without the Jacobian trf makes at its last point
    # (identification.trust_region): one evaluation per parameter fewer for the one start.
    assert (estimate.n_evaluations == expected["n_evaluations"] - len(theta)
            or not SAME_LIBRARIES or refit or reordered)
    _close(estimate.level_ratio, expected["level_ratio"], tolerance)
    _close(np.asarray(estimate.covariance).ravel(), expected["covariance"], tolerance)
    # Since issue 25 the profile covers the MSD's parameters; fitted step frequencies keep
    # their Wald interval (estimate ± z·SE of the sandwich, HSIEstimate.interval).
    profiled = {name: ends for name, ends in expected["intervals"].items()
                if key.endswith("bootstrap") or not name.startswith("step_frequency")}
    assert set(estimate.intervals) == set(profiled)
    for name, ends in profiled.items():
        if key.endswith("/profile"):
            # Since issue 28 §4 a profile's end is found to 1 % of the interval's half-width,
            # its inner fits to 1e-6 (docs: theory, Profile intervals), for a quarter less of
            # the estimate's time: the ends recorded to round-off agree to within that.
            half = (ends[1] - ends[0]) / 2
            np.testing.assert_allclose(estimate.intervals[name], ends, rtol=0, atol=0.01 * half)
        else:
            _close(estimate.intervals[name], ends, tolerance)
    if key.endswith("profile") and estimate.crowd is not None:
        for name in ("step_frequency_mean", "step_frequency_std"):
            half = 1.959963984540054 * np.sqrt(expected["covariance"][
                5 * estimate.free_parameters.index(name)])
            _close(estimate.interval(name),
                   [estimate.value(name) - half, estimate.value(name) + half], 1e-5)


def test_objective_is_immutable_and_a_refit_gets_a_new_one(measured):
    # Issue 26 §4: the estimate must not replace the objective's model in place.
    objective = PSDObjective(measured, BRIDGE, CROWD, band=(0.0, 10.0), method="least_squares")
    with pytest.raises(AttributeError, match="PSDObjective is immutable: model"):
        objective.model = objective.model_for((1.95, 0.2))
    refit = objective.with_step_frequencies((1.95, 0.2))
    assert refit is not objective
    assert (refit.model.crowd.step_frequency_mean, refit.model.crowd.step_frequency_std) == (
        1.95, 0.2)
    assert objective.model.crowd == CROWD       # the original keeps the crowd it was built for
    # The refit's misfit is the original's evaluated at those step frequencies (the same model).
    np.testing.assert_array_equal(refit.residuals(TRUTH),
                                  objective.residuals(TRUTH, steps=(1.95, 0.2)))


def test_rescaled_and_redrawn_objectives_leave_the_original_alone(measured):
    # docs: theory, Parametric bootstrap: a replicate's objective is a new one on new data.
    objective = PSDObjective(measured, BRIDGE, CROWD, band=(0.0, 10.0), method="least_squares")
    level, cost = objective.level.copy(), objective.cost(TRUTH)
    louder = objective.with_level(100.0)
    np.testing.assert_allclose(louder.level, 100.0 * level, rtol=1e-15)
    # The same data redrawn give the same misfit; doubled data a doubled level (its peak).
    assert objective.with_target(objective.target).cost(TRUTH) == cost
    np.testing.assert_allclose(objective.with_target(2.0 * objective.target).level, 2.0 * level,
                               rtol=1e-15)
    np.testing.assert_array_equal(objective.level, level)
    assert objective.cost(TRUTH) == cost


def test_joint_estimate_counts_every_records_evaluations(measured):
    # estimate_hsi_joint (docs: theory, Joint estimation): two identical records cost two forward
    # models per optimiser call, and their stacked misfit is twice the single record's.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        single = estimate_hsi(measured, BRIDGE, CROWD, band=(0.0, 10.0), interval=None,
                              starts=[(2.5, 0.4)], method="least_squares")   # joint's default
        joint = estimate_hsi_joint([measured, measured], BRIDGE, [CROWD, CROWD],
                                   band=(0.0, 10.0), interval=None, starts=[(2.5, 0.4)])
    assert joint.n_evaluations == 2 * single.n_evaluations
    assert joint.cost == pytest.approx(2 * single.cost, rel=1e-9)
    assert joint.msd.frequency == pytest.approx(single.msd.frequency, rel=1e-6)


def test_results_report_and_reference_share_one_vocabulary(measured):
    # Issue 26 §4: one table of quantities in the core, read by the result, the report's labels
    # and the docs' case-file reference (docs/_ext/casefile_keys.py).
    from crowdvib.quantities import QUANTITIES, describe, unit
    from crowdvib.reporting.html import label

    assert unit("step_frequency_mean") == "Hz" and unit("damping_ratio") == "-"
    assert unit("no_such_key") is None
    assert label("walking_speed") == describe("walking_speed") == "walking speed [m/s]"
    with pytest.raises(TypeError):
        QUANTITIES["walking_speed"] = ("speed", "km/h")     # read-only: one table for all
    estimate = _run(measured, "likelihood/smeared/True/wald")
    lines = estimate.summary().splitlines()
    # RECORDED (commit 89c377c): μ_fs = 1.888892... Hz, its Wald interval from the covariance.
    low, high = estimate.interval("step_frequency_mean")
    assert lines[2] == (f"mean step frequency [Hz]: {1.888892264946516:.4g} "
                        f"(95% interval {low:.4g} – {high:.4g})")
    assert [line.split(":")[0] for line in lines] == [
        "frequency [Hz]", "damping ratio [-]", "mean step frequency [Hz]",
        "step-frequency spread [Hz]"]


def test_objective_arrays_are_read_only(measured):
    # Immutable objective (issue 26 §4): its arrays cannot be changed in place either.
    objective = PSDObjective(measured, BRIDGE, CROWD, band=(0.0, 10.0), method="least_squares")
    with pytest.raises(ValueError, match="read-only"):
        objective.target[0, 0] = 0.0
    doubled = 2.0 * objective.target
    with pytest.raises(ValueError, match="read-only"):
        objective.with_target(doubled).target[0, 0] = 1.0
    doubled[0, 0] = 1.0         # the caller's array is the caller's: still writeable
    assert doubled[0, 0] == 1.0
