"""Modal models from FE exports: UFF 15 + 55 and CSV node tables (docs: theory, Modal models from FE exports; issue 13)."""

import numpy as np
import pytest

from crowdvib import DataError, DataWarning, ModalModel, ParameterError
from crowdvib.io import read_modal_model, write_modal_model
from crowdvib.io.femodes import read_fe_modes

pyuff = pytest.importorskip("pyuff")

SPAN, WIDTH, MASS = 50.0, 3.0, 50e3
FREQUENCIES = (2.0, 8.0)
DAMPING = (0.005, 0.01)


def six_digits(values):
    """Values as UFF 55 stores them: pyuff writes %13.5e (6 significant digits)."""
    return np.array([float(f"{v:.5e}") for v in np.ravel(values)]).reshape(np.shape(values))


@pytest.fixture
def beam():
    """The paper's 50 m beam with two sine modes (closed form), shapes rounded as UFF keeps them."""
    exact = ModalModel.simply_supported_beam(SPAN, WIDTH, list(FREQUENCIES), list(DAMPING), MASS,
                                             n_modes=2, n_points=101, outputs={"midspan": 25.0})
    return exact.replace(mode_shapes=six_digits(exact.mode_shapes),
                         output_shapes=six_digits(exact.output_shapes))


def write_uff(path, positions, shapes, masses, lateral=None, lines=(0.0,)):
    """UFF 15 (nodes 101…, one row of nodes per y in ``lines``) + one UFF 55 per mode, via pyuff."""
    x = np.tile(positions, len(lines))
    y = np.repeat(lines, positions.size)
    nodes = np.arange(101, 101 + x.size)
    sets = [{"type": 15, "node_nums": nodes, "def_cs": np.zeros(x.size, int),
             "disp_cs": np.zeros(x.size, int), "color": np.ones(x.size, int),
             "x": x, "y": y, "z": np.zeros(x.size)}]
    for j in range(shapes.shape[1]):
        r2 = np.zeros(x.size) if lateral is None else lateral[:, j]
        sets.append(pyuff.prepare_55(
            model_type=1, analysis_type=2, data_ch=2, spec_data_type=8, data_type=2,
            n_data_per_node=3, load_case=1, mode_n=j + 1, freq=FREQUENCIES[j % 2],
            modal_m=masses[j], modal_damp_vis=DAMPING[j % 2], modal_damp_his=0.0,
            r1=np.zeros(x.size), r2=r2, r3=shapes[:, j], node_nums=nodes))
    pyuff.UFF(str(path)).write_sets(sets, "overwrite")
    return nodes


def assert_same(a, b, tol=1e-10):
    for name in ("frequencies", "damping_ratios", "modal_masses", "mode_shapes", "output_shapes",
                 "positions"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=tol, atol=tol,
                                   err_msg=name)
    np.testing.assert_allclose(a.influence_matrix(0.5), b.influence_matrix(0.5), rtol=tol)


def test_uff_reads_back_into_the_csv_routes_model(beam, tmp_path, reference):
    write_modal_model(beam, tmp_path / "modes.csv", tmp_path / "shapes.csv")
    csv_model = read_modal_model(tmp_path / "modes.csv", tmp_path / "shapes.csv", width=WIDTH,
                                 outputs={"midspan": 25.0})
    write_uff(tmp_path / "beam.uff", beam.positions, beam.mode_shapes[0], [MASS, MASS])
    uff_model = read_modal_model(tmp_path / "beam.uff", width=WIDTH, outputs={"midspan": 25.0})
    assert_same(uff_model, csv_model)
    # and the closed form: Ψ_11 = d·∫∫φ² = 0.5 · 3 · 25 = 37.5 (docs: theory, paper example), to
    # the trapezoid rule on 51 stations and UFF's 6 digits
    reference("Ψ11 of a beam read from a UFF 15/55 export", uff_model.influence_matrix(0.5)[0, 0],
              37.5, rel=1e-3, unit="persons",
              source="closed form n/2 for a unity-scaled sine mode (docs: theory, The paper's "
                     "numerical example); 6-digit UFF values, trapezoid rule")


def test_mass_normalised_export_gets_the_engaged_modal_mass(beam, tmp_path):
    scale = 1 / np.sqrt(MASS)
    write_uff(tmp_path / "mass.uff", beam.positions, six_digits(beam.mode_shapes[0] * scale),
              [1.0, 1.0])
    modes = read_fe_modes(tmp_path / "mass.uff")
    assert modes.mass_normalised
    model = read_modal_model(tmp_path / "mass.uff", width=WIDTH, outputs={"midspan": 25.0})
    # m = 1/max|φ_mn|² = M for φ_mn = sin/√M (closed form), to the 6 digits UFF keeps
    np.testing.assert_allclose(model.modal_masses, [MASS, MASS], rtol=1e-5)
    np.testing.assert_allclose(model.mode_shapes, beam.mode_shapes, atol=1e-5)
    # the CSV node table with the same numbers and no modal_mass column: the same model
    node_csv = tmp_path / "nodes.csv"
    shapes = six_digits(beam.mode_shapes[0] * scale)
    rows = ["node,x,y,z,mode_1,mode_2"] + [
        f"{101 + i},{float(x)!r},0,0,{float(shapes[i, 0])!r},{float(shapes[i, 1])!r}" for i, x in
        enumerate(beam.positions)]
    node_csv.write_text("\n".join(rows) + "\n")
    (tmp_path / "table.csv").write_text("frequency,damping_ratio\n2.0,0.005\n8.0,0.01\n")
    csv_model = read_modal_model(tmp_path / "table.csv", node_csv, width=WIDTH,
                                 outputs={"midspan": 25.0})
    assert_same(csv_model, model)


def test_lateral_mode_dropped_with_a_warning_and_output_nodes(beam, tmp_path):
    shapes = np.column_stack([beam.mode_shapes[0][:, 0], 0.05 * beam.mode_shapes[0][:, 0]])
    lateral = np.column_stack([np.zeros(101), beam.mode_shapes[0][:, 0]])
    nodes = write_uff(tmp_path / "lat.uff", beam.positions, shapes, [MASS, MASS], lateral)
    with pytest.warns(DataWarning, match=r"dropped 1 mode.*mode 2 \(8 Hz, 0% vertical\)"):
        model = read_modal_model(tmp_path / "lat.uff", width=WIDTH,
                                 output_nodes={"quarter": int(nodes[25])})
    assert model.n_modes == 1
    # vertical share Σφ_z²/Σ(φ_y² + φ_z²) = 0.05²/(1 + 0.05²) = 0.25 % for mode 2 (closed form)
    fractions = read_fe_modes(tmp_path / "lat.uff").vertical_fractions()
    np.testing.assert_allclose(fractions, [1.0, 0.05**2 / (1 + 0.05**2)], rtol=1e-4)
    # node 126 sits at x = 12.5 m: sin(π/4)
    assert model.output_shapes[0, 0] == pytest.approx(np.sin(np.pi / 4), rel=1e-5)


def test_two_line_deck_gives_lanes_for_a_torsion_mode(beam, tmp_path):
    """Nodes on two edge lines y = ±1.5 m; mode 2 twists: φ = sin(πx/L)·y/1.5 (closed form)."""
    sine = beam.mode_shapes[0][:, 0]
    lines = (-1.5, 1.5)
    shapes = np.column_stack([np.tile(sine, 2), np.concatenate([-sine, sine])])
    write_uff(tmp_path / "deck.uff", beam.positions, shapes, [MASS, MASS], lines=lines)
    model = read_modal_model(tmp_path / "deck.uff", width=WIDTH, outputs={"mid": 25.0},
                             lanes=[0.0, 1.5, 3.0])
    np.testing.assert_allclose(model.lanes, [0.0, 1.5, 3.0])
    # scaled to +1 at its first largest |φ| (x = 25 m on the y = −1.5 m edge): the sign flips
    np.testing.assert_allclose(model.mode_shapes[:, :, 1], [sine, 0 * sine, -sine], atol=1e-12)
    np.testing.assert_allclose(model.mode_shapes[:, :, 0], [sine, sine, sine], atol=1e-12)


@pytest.mark.parametrize("options, error, pattern", [
    ({"along": "q"}, ParameterError, r"along must be one of \('x', 'y', 'z'\), got 'q'"),
    ({"along": "z"}, ParameterError, r"along, across and vertical must be three different axes"),
    ({"deck_nodes": [999]}, ParameterError, r"deck_nodes must be nodes of beam.uff"),
    ({"output_nodes": {"a": 7}}, ParameterError, r"output_nodes\['a'\] must be a node"),
    ({"damping_ratios": [0.01, 0.02, 0.03]}, ParameterError, r"one ratio per kept mode \(2\)"),
    ({"min_vertical": 1.5}, DataError, r"no mode is at least 150% vertical"),
])
def test_bad_fe_options(beam, tmp_path, options, error, pattern):
    write_uff(tmp_path / "beam.uff", beam.positions, beam.mode_shapes[0], [MASS, MASS])
    options = {"outputs": {"m": 25.0}, **options} if "output_nodes" not in options else options
    with pytest.raises(error, match=pattern), pytest.warns(DataWarning) if "min_vertical" in \
            options else _nothing():
        read_modal_model(tmp_path / "beam.uff", width=WIDTH, **options)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_station_csv_refuses_fe_options(beam, tmp_path):
    write_modal_model(beam, tmp_path / "modes.csv", tmp_path / "shapes.csv")
    with pytest.raises(ParameterError, match=r"\['along'\] apply to FE exports only"):
        read_modal_model(tmp_path / "modes.csv", tmp_path / "shapes.csv", width=WIDTH,
                         outputs={"m": 25.0}, along="x")


def test_a_case_file_names_a_uff_export(beam, tmp_path):
    # Issue 13: a case file may name an FE export instead of CSV tables; the model is the one
    # read_modal_model gives for the same file (itself checked against the CSV route above).
    from crowdvib import load_case

    nodes = write_uff(tmp_path / "beam.uff", beam.positions, beam.mode_shapes[0], [MASS, MASS])
    (tmp_path / "case.toml").write_text(
        f'[structure]\nmodal_table = "beam.uff"\nwidth = {WIDTH}\n'
        f'output_nodes = {{ midspan = {int(nodes[50])} }}\n'
        '[crowd]\ndensity = 0.5\n')
    case = load_case(tmp_path / "case.toml")
    direct = read_modal_model(tmp_path / "beam.uff", width=WIDTH,
                              output_nodes={"midspan": int(nodes[50])})
    assert_same(case.structure, direct, tol=1e-12)
    assert case.structure.output_names == ("midspan",)
    # midspan node of a unity-scaled first sine mode: φ = 1 (closed form, UFF's 6 digits)
    assert case.structure.output_shapes[0, 0] == pytest.approx(1.0, abs=1e-5)
    (tmp_path / "bad.toml").write_text(
        f'[structure]\nmodal_table = "beam.uff"\nwidth = {WIDTH}\n'
        'output_nodes = { midspan = "x" }\n[crowd]\ndensity = 0.5\n')
    with pytest.raises(ParameterError, match="structure.output_nodes must be a table"):
        load_case(tmp_path / "bad.toml")
