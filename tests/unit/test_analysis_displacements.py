"""The per-unit displacement columns of ``riprap analyse`` (units.csv, report, pictures), on cases
whose answer is known by construction.

Known answer: between frame 0 and frame 1 of a hand-written run, unit 0 is turned by 40 degrees
about the axis (1, 2, 2)/3 through its centroid and its centroid is moved by (0.3, -0.2, 0.1) m,
|d| = sqrt(0.14) = 0.3742 m; unit 1 does not move. The run is written as a coupled run writes it
(``bodies.pvd`` beside ``fluid.pvd``, no ``contacts.pvd``, ``summary.json`` naming a case that
includes the pack with ``pack = "..."``), so the analysis must find the layer through the
included pack and say that no contacts were recorded.
"""
import json
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from riprap.analysis import LayerDescription
from riprap.workflows.analyse import analyse
from riprap.analysis.displacements import DISPLACEMENT_COLUMNS, unit_displacements
from riprap.errors import CaseFileError
from riprap.geometry.armour_units import armour_unit
from riprap.io.layer_file import write_contact_table, write_layer_file
from riprap.io.pack import PackBody, write_pack
from riprap.io.summary import write_json
from riprap.io.vtk import ParaViewSeries
from riprap.placement.slope import Slope
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import ContactRecords

MOVE = np.array([0.3, -0.2, 0.1])
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
ANGLE_DEG = 40.0
TURN = Rotation.from_rotvec(math.radians(ANGLE_DEG) * AXIS).as_matrix()


def test_a_known_translation_and_rotation_give_their_length_and_angle():
    slope = Slope(cotangent=2.0, width=3.0, length=4.0)
    up_the_face = np.array([2.0, 0.0, 1.0]) / math.sqrt(5.0)     # 1:2 face, x up the slope
    start = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 1.5]])
    now = start + np.array([MOVE, 0.5 * up_the_face])
    reference_rotations = np.stack([np.eye(3), Rotation.from_euler("z", 30, degrees=True).as_matrix()])
    rotations = np.stack([TURN, reference_rotations[1]])
    moved = unit_displacements(now, rotations, start, reference_rotations, nominal_diameter=0.5,
                               slope=slope)
    assert list(moved) == list(DISPLACEMENT_COLUMNS)
    assert moved["displacement_m"] == pytest.approx([math.sqrt(0.14), 0.5], abs=1e-12)
    assert moved["displacement_over_dn"] == pytest.approx([math.sqrt(0.14) / 0.5, 1.0], abs=1e-12)
    assert moved["displacement_x_m"][0] == pytest.approx(0.3, abs=1e-12)
    assert moved["displacement_z_m"][0] == pytest.approx(0.1, abs=1e-12)
    assert moved["displacement_along_slope_m"][1] == pytest.approx(0.5, abs=1e-12)
    # Unit 1 keeps its (turned) orientation: no rotation, whatever the orientation it had.
    assert moved["rotation_deg"] == pytest.approx([ANGLE_DEG, 0.0], abs=1e-9)


def test_rotations_beyond_a_half_turn_read_as_the_shorter_way_round():
    turn = Rotation.from_rotvec(math.radians(270.0) * np.array([0.0, 0.0, 1.0])).as_matrix()
    moved = unit_displacements([[0.0, 0.0, 0.0]], turn[None], [[0.0, 0.0, 0.0]], np.eye(3)[None],
                               nominal_diameter=1.0)
    assert moved["rotation_deg"][0] == pytest.approx(90.0, abs=1e-9)
    assert math.isnan(moved["displacement_along_slope_m"][0])         # no slope given


def _no_contacts():
    return ContactRecords(body_i=np.zeros(0, np.int64), body_j=np.zeros(0, np.int64),
                          points=np.zeros((0, 3)), normal_forces=np.zeros((0, 3)),
                          tangential_forces=np.zeros((0, 3)), stiffness=np.zeros(0))


def _surface(mesh, rotation, position, centroid):
    """A body's surface as a frame writes it: nodes in the stored mesh's order, in the world."""
    faces = mesh.boundary_faces()
    used, local = np.unique(faces, return_inverse=True)
    return (mesh.nodes[used] - centroid) @ rotation.T + position, local.reshape(faces.shape)


@pytest.fixture(scope="module")
def coupled_run(tmp_path_factory):
    """Two Core-Loc-like units in a pack, a case that puts the pack in water, and a run folder
    of that case with two frames: unit 0 moved and turned in frame 1, unit 1 still."""
    from riprap.geometry.mass_properties import mass_properties

    root = tmp_path_factory.mktemp("coupled")
    unit = armour_unit("core_loc_like", height=1.0, density=2400.0, mesh_size=0.5)
    shape = RigidShape.from_mesh(unit.mesh, name="armour_unit")
    slope = Slope(cotangent=1.5, width=3.0, length=4.0)
    positions = np.array([slope.to_world(1.5, 0.8, 0.6), slope.to_world(1.5, 2.2, 0.6)])
    concrete = Material(name="concrete", density=2400.0, friction_coefficient=0.0,
                        restitution=0.3, contact_penalty=1e8)
    write_pack(root / "pack", shapes={"armour_unit": shape.mesh}, materials=[concrete],
               bodies=[PackBody(shape="armour_unit", material="concrete", position=tuple(p),
                                orientation=(1.0, 0.0, 0.0, 0.0)) for p in positions],
               walls=slope.walls(face_material="concrete", side_material="concrete"))
    write_layer_file(root / "pack", LayerDescription.for_unit(
        unit, shape, slope=slope, underlayer_top=0.0, unit_bodies=[0, 1], rows=[0, 0],
        design_positions=positions))
    write_contact_table(root / "pack" / "contacts.csv", _no_contacts())
    case = root / "in_water.toml"
    case.write_text('format_version = 1\npack = "pack/pack.toml"\n[simulation]\nend_time = 1.0\n'
                    "[fluid]\nlower = [-1.0, 0.0, 0.0]\nupper = [4.0, 3.0, 3.0]\n"
                    "cells = [50, 30, 30]\n[[water_regions]]\ntype = \"level\"\nlevel = 1.0\n")
    run = root / "run"
    run.mkdir()
    write_json(run / "summary.json", {"case_file": str(case), "simulated_time": 1.0})
    (run / "fluid.pvd").write_text("<VTKFile type='Collection'><Collection/></VTKFile>")
    centroid = mass_properties(shape.mesh, density=1.0).centroid
    series = ParaViewSeries(run, "bodies")
    for time, (first_rotation, first_position) in ((0.0, (np.eye(3), positions[0])),
                                                   (1.0, (TURN, positions[0] + MOVE))):
        poses = [(first_rotation, first_position), (np.eye(3), positions[1])]
        points, triangles, owners, offset = [], [], [], 0
        for body, (rotation, position) in enumerate(poses):
            world, faces = _surface(shape.mesh, rotation, position, centroid)
            points.append(world)
            triangles.append(faces + offset)
            owners.append(np.full(len(faces), body, dtype=np.int64))
            offset += len(world)
        series.add(time, points=np.concatenate(points), cells=np.concatenate(triangles),
                   cell_type="triangle", cell_data={"body_id": np.concatenate(owners)})
    return run


def test_a_coupled_run_gives_each_units_displacement_and_rotation_since_frame_0(coupled_run,
                                                                               tmp_path):
    out = tmp_path / "analysis"
    analysis = analyse(coupled_run, out=out, frame=1)
    units, layer = analysis.units, analysis.layer
    dn = analysis.state.layer.nominal_diameter
    assert units["displacement_m"] == pytest.approx([math.sqrt(0.14), 0.0], abs=1e-9)
    assert units["displacement_over_dn"] == pytest.approx([math.sqrt(0.14) / dn, 0.0], abs=1e-9)
    assert units["rotation_deg"] == pytest.approx([ANGLE_DEG, 0.0], abs=1e-6)
    assert [units[f"displacement_{c}_m"][0] for c in "xyz"] == pytest.approx(MOVE, abs=1e-9)
    assert layer["units_moved"] == [0]
    assert layer["max_rotation_deg"] == pytest.approx(ANGLE_DEG, abs=1e-6)
    assert layer["displacement_reference_time_s"] == 0.0
    # damage: moved less than one D_n, so nothing displaced (N_od 0); turned once, never back
    assert layer["units_displaced"] == [] and layer["damage_number_nod"] == 0.0
    assert list(units["rocking_events"]) == [0, 0] and layer["rocking_events"] == 0
    # the moved unit uncovers part of its old place: the cross-section's surface went down there
    assert layer["eroded_area_m2"] > 0.0
    assert layer["damage_level_s"] == pytest.approx(layer["eroded_area_m2"] / dn ** 2)
    # The same numbers in units.csv; the contact columns are empty, not zero.
    lines = (out / "units.csv").read_text().splitlines()
    rows = [dict(zip(lines[0].split(","), line.split(","))) for line in lines[1:]]
    assert float(rows[0]["displacement_m"]) == pytest.approx(math.sqrt(0.14), abs=1e-9)
    assert float(rows[0]["rotation_deg"]) == pytest.approx(ANGLE_DEG, abs=1e-6)
    assert rows[0]["coordination_number"] == "nan" and rows[0]["factor_of_safety"] == "nan"
    assert layer["contacts_recorded"] is False and layer["coordination_number_mean"] is None
    summary = json.loads((out / "layer_summary.json").read_text())
    assert summary["max_displacement_m"] == pytest.approx(math.sqrt(0.14), abs=1e-9)
    report = (out / "report.html").read_text()
    assert "<h2>Displacements</h2>" in report and "recorded no contacts" in report
    assert "slope_displacement_over_dn.svg" in report
    assert (out / "layer_displacement_over_dn.png").is_file()
    assert not (out / "layer_coordination_number.png").exists()       # nothing to draw


def test_frame_0_of_a_run_has_not_moved_and_a_pack_has_no_reference(coupled_run, tmp_path):
    at_start = analyse(coupled_run, frame=0)
    assert at_start.units["displacement_m"] == pytest.approx([0.0, 0.0], abs=1e-9)
    assert at_start.units["rotation_deg"] == pytest.approx([0.0, 0.0], abs=1e-6)
    assert at_start.layer["eroded_area_m2"] == 0.0 and at_start.layer["damage_level_s"] == 0.0
    pack = analyse(coupled_run.parent / "pack", out=tmp_path / "pack_analysis")
    assert np.isnan(pack.units["displacement_m"]).all()
    assert "no earlier state" in pack.layer["displacement_reference"]
    assert "max_displacement_m" not in pack.layer
    assert not (tmp_path / "pack_analysis" / "layer_displacement_over_dn.png").exists()


def test_a_flume_run_gets_its_stability_report(coupled_run, tmp_path):
    """A run folder with a waves report: ``riprap analyse`` adds the flume test's stability report
    (the measured waves' stability number beside Hudson's) to the layer summary."""
    import shutil

    run = tmp_path / "flume_run"
    shutil.copytree(coupled_run, run)
    (run / "waves_report.json").write_text(json.dumps(
        {"water_density_kg_m3": 1000.0, "gauges": {"g1": {"Hm0_m": 0.7, "Tz_s": 3.0, "waves": 20}},
         "reflection": []}))
    analysis = analyse(run, out=tmp_path / "analysis", frame=1)
    flume = analysis.layer["flume_test"]
    dn = analysis.state.layer.nominal_diameter
    assert flume["stability_number"] == pytest.approx(0.7 / (1.4 * dn))
    assert flume["hudson"]["K_D"] == 16.0 and flume["units_displaced"] == 0
    summary = json.loads((tmp_path / "analysis" / "layer_summary.json").read_text())
    assert summary["flume_test"]["Hm0_m"] == 0.7
    # a damaged waves report is named, not a traceback
    (run / "waves_report.json").write_text("{not json")
    with pytest.raises(CaseFileError, match="waves_report.json: cannot read the waves report"):
        analyse(run, frame=1)
