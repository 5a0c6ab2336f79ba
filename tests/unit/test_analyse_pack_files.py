"""riprap analyse on hand-written packs: a unit at a known orientation lands at its known place on
the stereonet, every output file is written, and bad packs are refused with messages that name
the file and what is missing.

Known orientation: a Core-Loc-like unit whose nose (trunk) axis points down to the south-east,
trend 135 degrees, plunge 30 degrees. On a lower-hemisphere equal-area net of unit radius it plots
at r = sqrt(2) sin((90 - 30) / 2 degrees) = 0.7071 from the centre, in the direction of the trend:
(east, north) = (0.5, -0.5) (Lambert azimuthal equal-area projection; worked by hand).
"""
import json
import math

import matplotlib
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.analysis import LayerDescription
from riprap.workflows.analyse import analyse
from riprap.errors import CaseFileError
from riprap.geometry.armour_units import armour_unit
from riprap.io.layer_file import (CONTACT_COLUMNS, read_contact_table, write_contact_table,
                                  write_layer_file)
from riprap.io.pack import PackBody, write_pack
from riprap.placement.slope import Slope
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import ContactRecords

TREND, PLUNGE = 135.0, 30.0
NOSE = np.array([math.cos(math.radians(PLUNGE)) * math.sin(math.radians(TREND)),
                 math.cos(math.radians(PLUNGE)) * math.cos(math.radians(TREND)),
                 -math.sin(math.radians(PLUNGE))])
EXPECTED_NET_POINT = np.array([0.5, -0.5])


def _no_contacts():
    return ContactRecords(body_i=np.zeros(0, np.int64), body_j=np.zeros(0, np.int64),
                          points=np.zeros((0, 3)), normal_forces=np.zeros((0, 3)),
                          tangential_forces=np.zeros((0, 3)), stiffness=np.zeros(0))


@pytest.fixture(scope="module")
def pack(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pack")
    unit = armour_unit("core_loc_like", height=1.0, density=2400.0, mesh_size=0.5)
    shape = RigidShape.from_mesh(unit.mesh, name="armour_unit")
    # The rotation that takes the unit's nose (its x axis as built) onto NOSE, applied to the
    # principal-frame mesh that the pack stores (built = A principal + c).
    turn, _ = Rotation.align_vectors([NOSE], [unit.axes["nose"]])
    x, y, z, w = Rotation.from_matrix(turn.as_matrix() @ shape.frame_rotation).as_quat()
    slope = Slope(cotangent=1.5, width=3.0, length=4.0)
    position = slope.to_world(2.0, 1.5, 0.6)
    concrete = Material(name="concrete", density=2400.0, friction_coefficient=0.6,
                        restitution=0.3, contact_penalty=1e8)
    write_pack(folder, shapes={"armour_unit": shape.mesh}, materials=[concrete],
               bodies=[PackBody(shape="armour_unit", material="concrete", position=tuple(position),
                                orientation=(w, x, y, z))],
               walls=slope.walls(face_material="concrete", side_material="concrete"))
    write_layer_file(folder, LayerDescription.for_unit(
        unit, shape, slope=slope, underlayer_top=0.0, unit_bodies=[0], rows=[0],
        design_positions=[position]))
    write_contact_table(folder / "contacts.csv", _no_contacts())
    return folder


def test_a_unit_at_a_known_orientation_has_its_known_trend_plunge_and_net_point(pack, tmp_path):
    analysis = analyse(pack, out=tmp_path / "analysis")
    units = analysis.units
    assert units["nose_trend_deg"][0] == pytest.approx(TREND, abs=1e-9)
    assert units["nose_plunge_deg"][0] == pytest.approx(PLUNGE, abs=1e-9)
    assert units["nose_net_east"][0] == pytest.approx(EXPECTED_NET_POINT[0], abs=1e-12)
    assert units["nose_net_north"][0] == pytest.approx(EXPECTED_NET_POINT[1], abs=1e-12)
    # The same numbers in units.csv, which has at least the columns.
    lines = (tmp_path / "analysis" / "units.csv").read_text().splitlines()
    header = lines[0].split(",")
    for column in ("unit_id", "coordination_number", "max_contact_force_N", "factor_of_safety"):
        assert column in header
    row = dict(zip(header, lines[1].split(",")))
    assert float(row["nose_trend_deg"]) == pytest.approx(TREND, abs=1e-9)
    for name in ("report.html", "stereonet.png", "stereonet.svg", "layer.vtu", "histograms.svg",
                 "slope_factor_of_safety.svg", "layer_summary.json", "contacts.csv"):
        assert (tmp_path / "analysis" / name).is_file(), name
    report = (tmp_path / "analysis" / "report.html").read_text()
    assert "stereonet.svg" in report and "units.csv" in report
    # Touching nothing: coordination number 0 and no support against rocking.
    assert units["coordination_number"].tolist() == [0]
    assert units["factor_of_safety_rocking"][0] == 0.0


def test_the_stereonet_draws_the_unit_at_its_net_point():
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import mplstereonet  # noqa: F401

    from riprap.io.analysis_figures import _draw_stereonet

    figure = plt.figure(figsize=(5, 5))
    axes = figure.add_subplot(111, projection="stereonet")
    _draw_stereonet(axes, np.array([TREND]), np.array([PLUNGE]), "")
    figure.canvas.draw()
    marker = axes.lines[-1]
    to_display = axes.transData.transform
    drawn = to_display(np.column_stack(marker.get_data()))[0]
    centre = to_display([[0.0, 0.0]])[0]
    east = to_display([[np.pi / 2, 0.0]])[0]        # the net's east edge: radius 1
    north = to_display([[0.0, np.pi / 2]])[0]
    net_point = np.array([(drawn - centre)[0] / (east - centre)[0],
                          (drawn - centre)[1] / (north - centre)[1]])
    plt.close(figure)
    assert np.allclose(net_point, EXPECTED_NET_POINT, atol=1e-6)


def test_contact_table_round_trips_exactly(tmp_path):
    records = ContactRecords(body_i=np.array([0, 3]), body_j=np.array([2, -1]),
                             points=np.array([[0.1, 0.2, 1 / 3], [1.0, 2.0, 3.0]]),
                             normal_forces=np.array([[0.0, 0.0, 9.81e3], [1e-300, 2.0, 3.0]]),
                             tangential_forces=np.array([[np.pi, 0.0, 0.0], [0.0, -1.5, 0.0]]),
                             stiffness=np.zeros(2))
    back = read_contact_table(write_contact_table(tmp_path / "c.csv", records))
    for field in ("body_i", "body_j", "points", "normal_forces", "tangential_forces"):
        assert np.array_equal(getattr(back, field), getattr(records, field)), field


def _copy_pack(source, target):
    import shutil

    shutil.copytree(source, target)
    return target


def test_a_pack_without_a_layer_description_is_refused(pack, tmp_path):
    folder = _copy_pack(pack, tmp_path / "p")
    (folder / "layer.json").unlink()
    with pytest.raises(CaseFileError, match=r"layer.json: missing.*riprap place"):
        analyse(folder)


def test_missing_fields_and_other_versions_are_named(pack, tmp_path):
    folder = _copy_pack(pack, tmp_path / "p")
    data = json.loads((folder / "layer.json").read_text())
    del data["rows"], data["unit_axes"]
    (folder / "layer.json").write_text(json.dumps(data))
    with pytest.raises(CaseFileError, match=r"missing field\(s\): 'unit_axes' .*'rows'"):
        analyse(folder)
    data = json.loads((pack / "layer.json").read_text())
    data["format_version"] = 2
    (folder / "layer.json").write_text(json.dumps(data))
    with pytest.raises(CaseFileError, match="format_version 2; this riprap reads .* 1"):
        analyse(folder)


def test_bad_contact_tables_are_named_with_their_line(pack, tmp_path):
    folder = _copy_pack(pack, tmp_path / "p")
    (folder / "contacts.csv").unlink()
    with pytest.raises(CaseFileError, match="contacts.csv: missing"):
        analyse(folder)
    numbers = ",".join(["0", "7"] + ["1.0"] * (len(CONTACT_COLUMNS) - 2))
    (folder / "contacts.csv").write_text(",".join(CONTACT_COLUMNS) + "\n" + numbers + "\n")
    with pytest.raises(CaseFileError, match="contact 0 joins body 0 and 7, but there are 1 bodies"):
        analyse(folder)
    (folder / "contacts.csv").write_text(",".join(CONTACT_COLUMNS) + "\n0,1,x\n")
    with pytest.raises(CaseFileError, match=r"contacts.csv:2: not all fields are numbers"):
        analyse(folder)


def test_a_missing_path_is_named(tmp_path):
    with pytest.raises(CaseFileError, match="no such pack or run folder"):
        analyse(tmp_path / "nowhere")


def test_frames_of_a_run_started_from_the_pack_are_analysed(pack, tmp_path, monkeypatch):
    from riprap.case.build import build_simulation
    from riprap.case.load import load_case

    monkeypatch.setenv("RIPRAP_SMOKE", "1")          # a 0.01 s run: the unit falls freely
    sim = build_simulation(load_case(pack / "pack.toml"), output_directory=tmp_path / "run",
                           progress=False)
    summary = sim.run()
    assert summary.case_file == str((pack / "pack.toml").resolve())
    first = analyse(tmp_path / "run", frame=0)
    last = analyse(tmp_path / "run", out=tmp_path / "run_analysis")
    # Poses fitted from the frames' surfaces: the start pose exactly, then a free fall.
    assert first.units["nose_trend_deg"][0] == pytest.approx(TREND, abs=1e-7)
    assert first.units["nose_plunge_deg"][0] == pytest.approx(PLUNGE, abs=1e-7)
    assert last.units["nose_plunge_deg"][0] == pytest.approx(PLUNGE, abs=1e-7)
    drop = first.units["z_m"][0] - last.units["z_m"][0]
    fall_time = last.state.time - first.state.time
    assert drop == pytest.approx(0.5 * 9.81 * fall_time ** 2, rel=1e-6)
    assert "t = " in last.layer["source"]
    with pytest.raises(CaseFileError, match="frame 7 does not exist"):
        analyse(tmp_path / "run", frame=7)


def test_two_packs_are_compared_side_by_side(pack, tmp_path):
    from riprap.workflows.analyse import compare_layers

    other = _copy_pack(pack, tmp_path / "other")
    analyses = compare_layers([pack, other], out=tmp_path / "cmp", labels=["first", "second"])
    assert [a.units["nose_trend_deg"][0] for a in analyses] == pytest.approx([TREND, TREND])
    for name in ("comparison.html", "comparison_stereonets.svg", "comparison_histograms.png",
                 "first/report.html", "second/units.csv"):
        assert (tmp_path / "cmp" / name).is_file(), name
    page = (tmp_path / "cmp" / "comparison.html").read_text()
    assert "first" in page and "second" in page
    with pytest.raises(CaseFileError, match="two or more"):
        compare_layers([pack], out=tmp_path / "one")


def test_command_line_analyse(pack, tmp_path, capsys):
    from riprap.cli import main

    assert main(["analyse", str(pack), "--out", str(tmp_path / "a")]) == 0
    assert "report:" in capsys.readouterr().out
    assert main(["analyse", str(tmp_path / "missing")]) == 2
    assert "no such pack or run folder" in capsys.readouterr().err


def test_the_3d_and_face_views_of_a_field_share_one_colour_scale(pack, tmp_path, monkeypatch):
    from matplotlib.collections import PolyCollection

    from riprap.io import analysis_figures, picture

    analysis = analyse(pack)
    drawn, saved = {}, {}
    monkeypatch.setattr(picture, "render_bodies_png", lambda path, **given: drawn.update(given))

    def keep_scale(figure, path, formats=("png", "svg")):
        footprints = [c for c in figure.axes[0].collections if isinstance(c, PolyCollection)]
        saved.update(colour_map=footprints[0].get_cmap().name, range=footprints[0].get_clim())
        matplotlib.pyplot.close(figure)
        return []

    monkeypatch.setattr(analysis_figures, "_save", keep_scale)
    for column, (_, colour_map) in analysis_figures.PER_UNIT_FIELDS.items():
        analysis_figures.layer_view_png(tmp_path / "layer.png", analysis, column)
        analysis_figures.slope_view_figure(tmp_path / "slope.png", analysis, column)
        assert drawn["colour_map"] == saved["colour_map"] == colour_map, column
        assert tuple(drawn["value_range"]) == pytest.approx(saved["range"], abs=1e-12), column
        if column == "factor_of_safety":
            # The unit touches nothing (factor of safety 0): the scale is still 0 to the cap.
            assert saved["range"] == pytest.approx(
                (0.0, analysis_figures.FACTOR_OF_SAFETY_DISPLAY_CAP))
