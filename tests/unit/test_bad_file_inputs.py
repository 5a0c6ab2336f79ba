"""Bad file inputs give a named riprap error that names the file (issue 12), never a traceback,
a ``sys.exit`` from a library or a silently wrong answer.

One test per kind: mesh files (meshio's ``sys.exit`` on empty or truncated files, face indices
out of range, repeated or overlapping tetrahedra, non-finite coordinates, no or wrong cells);
absurd shape sizes and mesh sizes refused before gmsh is called; analysis inputs (``layer.json``
fields, ``contacts.csv`` rows, frames of a run folder); non-finite numbers in JSON outputs.
Every broken file is built in ``tmp_path``; nothing here calls gmsh.
"""
import json
import math

import meshio
import numpy as np
import pytest

from riprap.analysis.layer_state import LayerDescription
from riprap.errors import CaseFileError, MeshError
from riprap.geometry import shapes
from riprap.geometry.armour_units import armour_unit
from riprap.geometry.tetmesh import TetMesh
from riprap.workflows.layer_input import load_run_state
from riprap.io.layer_file import (CONTACT_COLUMNS, read_contact_table, read_layer_file,
                                  write_layer_file)
from riprap.io.mesh_files import read_mesh
from riprap.io.summary import write_json
from riprap.placement.slope import Slope

CUBE_NODES = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                       [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
CUBE_TETS = TetMesh.from_arrays(
    CUBE_NODES, [[0, 1, 3, 4], [1, 2, 3, 6], [1, 4, 5, 6], [3, 4, 6, 7], [1, 3, 4, 6]],
    fix_orientation=True).tets
TETRAHEDRON_OBJ_VERTICES = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"


def _write_vtu(path, nodes, cells):
    meshio.write_points_cells(path, nodes, cells)
    return path


def _ply(face_lines):
    header = ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
              "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
              "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n")
    return header + "".join(face_lines)


def _broken_meshes(tmp_path):
    """(file, words the message must hold) for each kind of broken mesh file."""
    good = _write_vtu(tmp_path / "good.vtu", CUBE_NODES, [("tetra", CUBE_TETS)])
    text = good.read_bytes()
    cases = []

    def add(name, content, *words):
        path = tmp_path / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        elif isinstance(content, str):
            path.write_text(content)
        cases.append((path, words))

    add("empty.vtu", b"", "empty")
    add("truncated.vtu", text[: len(text) // 2], "could not be read")
    add("empty.ply", b"", "empty")
    add("truncated.ply", _ply(["3 0 2 1\n", "3 0 1 3\n"]), "could not be read")
    add("junk.vtu", "<VTKFile>not really", "could not be read")
    add("index.obj", TETRAHEDRON_OBJ_VERTICES + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 9\n",
        "face 4 (vertex 9)")
    add("zero_index.obj", TETRAHEDRON_OBJ_VERTICES + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 0\n",
        "face 4 (vertex 0)")
    add("index.ply", _ply(["3 0 2 1\n", "3 0 1 3\n", "3 0 3 2\n", "3 1 2 17\n"]),
        "face 3 (vertex 17)")
    add("nan.obj", TETRAHEDRON_OBJ_VERTICES.replace("v 1 0 0", "v 1 0 nan")
        + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", "non-finite", "2 [1.0, 0.0, nan]")
    add("pentagon.obj", TETRAHEDRON_OBJ_VERTICES + "v 1 1 1\nf 1 3 2\nf 1 2 4 5 3\n",
        "polygon", "face 2")
    repeated = np.vstack([CUBE_TETS, CUBE_TETS[4][[1, 2, 0, 3]]])
    _write_vtu(tmp_path / "repeated.vtu", CUBE_NODES, [("tetra", repeated)])
    cases.append((tmp_path / "repeated.vtu", ("repeated tetrahedra", "tets [4, 5]")))
    # A sixth tetrahedron on an inner face of the cube: that face is shared by three.
    inner = TetMesh.from_arrays(np.vstack([CUBE_NODES, [[0.3, 0.3, 0.3]]]),
                                np.vstack([CUBE_TETS, [[1, 3, 4, 8]]]), fix_orientation=True)
    _write_vtu(tmp_path / "three_on_a_face.vtu", inner.nodes, [("tetra", inner.tets)])
    cases.append((tmp_path / "three_on_a_face.vtu", ("more than two tetrahedra", "tets [")))
    nodes = CUBE_NODES.copy()
    nodes[6, 1] = np.inf
    _write_vtu(tmp_path / "infinite.vtu", nodes, [("tetra", CUBE_TETS)])
    cases.append((tmp_path / "infinite.vtu", ("non-finite", "vertex: 6")))
    _write_vtu(tmp_path / "outside.vtu", CUBE_NODES, [("tetra", np.vstack([CUBE_TETS, [[0, 1, 2, 99]]]))])
    cases.append((tmp_path / "outside.vtu", ("tetrahedron 5 (vertex 99)",)))
    _write_vtu(tmp_path / "triangles.vtu", CUBE_NODES, [("triangle", CUBE_TETS[:, :3])])
    cases.append((tmp_path / "triangles.vtu", ("no tetrahedra", "triangle")))
    _write_vtu(tmp_path / "hexahedra.vtu", CUBE_NODES,
               [("tetra", CUBE_TETS[:1]), ("hexahedron", np.arange(8)[None])])
    cases.append((tmp_path / "hexahedra.vtu", ("hexahedron",)))
    add("no_faces.obj", TETRAHEDRON_OBJ_VERTICES, "no triangle or quad faces")
    return cases


def test_broken_mesh_files_raise_mesh_error_naming_the_file_and_element(tmp_path):
    cases = _broken_meshes(tmp_path)
    for path, words in cases:
        try:
            read_mesh(path)
        except MeshError as error:
            message = str(error)
        except BaseException as error:  # SystemExit from meshio included
            pytest.fail(f"{path.name}: {type(error).__name__} instead of MeshError: {error}")
        else:
            pytest.fail(f"{path.name}: read without error")
        assert path.name in message, (path.name, message)
        for word in words:
            assert word in message, (path.name, word, message)


def test_absurd_shape_sizes_and_mesh_sizes_are_refused_before_meshing():
    cases = [
        (lambda: shapes.sphere(radius=1e308), ("radius", "1e+308")),
        (lambda: shapes.sphere(radius=float("nan")), ("radius", "nan")),
        (lambda: shapes.sphere(radius="big"), ("radius", "'big'")),
        (lambda: shapes.box(lengths=(1.0, 1.0, 1e-9)), ("lengths", "1e-09")),
        (lambda: shapes.sphere(radius=1.0, mesh_size=1e-3), ("mesh_size", "2.51e+10 tetrahedra")),
        (lambda: shapes.cube(side=1.0, mesh_size=1e-3), ("mesh_size", "6e+09 tetrahedra")),
        (lambda: shapes.random_rock(size=0.1, n_vertices=1e8), ("n_vertices", "1e+08")),
        (lambda: shapes.random_rock(size=0.1, elongation=1e300), ("elongation", "1e+300")),
        (lambda: shapes.tetrapod(height=float("inf")), ("height", "inf")),
        (lambda: armour_unit("cube", height=1e308), ("height", "1e+308")),
        (lambda: armour_unit("cube", height=1.0, mesh_size=1e-4), ("mesh_size", "6e+12 tetrahedra")),
    ]
    for build, words in cases:
        with pytest.raises(CaseFileError) as error:
            build()
        for word in words:
            assert word in str(error.value), (word, str(error.value))


# ---------------------------------------------------------------- analysis inputs

def _layer(n_units=1):
    slope = Slope(cotangent=1.5, width=3.0, length=4.0)
    return LayerDescription(
        unit_kind="cube", unit_shape="cube", nominal_diameter=1.0, unit_volume=1.0,
        unit_height=1.0, unit_axes={"nose": np.array([0.0, 0.0, 1.0])}, slope=slope,
        underlayer_top=0.0, unit_bodies=np.arange(n_units), rows=np.zeros(n_units, int),
        design_positions=np.array([slope.to_world(2.0, 1.5, 0.6)] * n_units),
        design={"packing_density_coefficient": 0.6, "layer_thickness_m": 1.0, "porosity": 0.5})


def test_bad_layer_file_fields_are_named_with_file_line_and_field(tmp_path):
    write_layer_file(tmp_path, _layer())
    good = json.loads((tmp_path / "layer.json").read_text())
    breakages = [
        ("nominal_diameter_m", "0.5", "'nominal_diameter_m' must be a finite number, got '0.5'"),
        ("unit_height_m", True, "'unit_height_m' must be a finite number"),
        ("rows", [0.0], "'rows' must be a list of integers >= 0; entry 0 is 0.0"),
        ("unit_bodies", ["0"], "'unit_bodies' must be a list of integers"),
        ("design_positions", [[1.0, 2.0]], "'design_positions' must be a list of [x, y, z]"),
        ("design_positions", [[1.0, "a", 2.0]], "entry 0 is [1.0, 'a', 2.0]"),
        ("unit_axes", {"nose": [0.0, 0.0, "up"]}, "axis 'nose' must be [x, y, z]"),
        ("slope", dict(good["slope"], cotangent="steep"), "'slope': 'cotangent' must be a finite"),
        ("design", {"porosity": "high"}, "'design': 'porosity' must be a finite number"),
        ("rows", [0, 1], "'rows' has 2 entries, 'unit_bodies' 1"),
        ("unit_shape", [], "'unit_shape' must be a shape name or a non-empty list of them"),
        ("unit_shape", ["stone_0", 3], "'unit_shape' must be a shape name or a non-empty list"),
        ("unit_axes", {}, "'unit_axes' must map axis names to [x, y, z] (the primary axis"),
    ]
    for field, value, expected in breakages:
        data = dict(good, **{field: value})
        text = json.dumps(data, indent=1)
        (tmp_path / "layer.json").write_text(text)
        line = next(k for k, row in enumerate(text.splitlines(), 1) if f'"{field}"' in row)
        with pytest.raises(CaseFileError) as error:
            read_layer_file(tmp_path)
        message = str(error.value)
        assert f"layer.json:{line}: " in message, (field, message)
        assert expected in message, (field, message)
    # rock armour's layer needs the design the rock analysis reads: named at the design's line
    text = json.dumps(dict(good, unit_kind="armour_stone"), indent=1)
    (tmp_path / "layer.json").write_text(text)
    line = next(k for k, row in enumerate(text.splitlines(), 1) if '"design"' in row)
    with pytest.raises(CaseFileError, match=rf"layer.json:{line}: a rock layer's 'design' needs "
                                            "'layers', 'dn50_m'"):
        read_layer_file(tmp_path)
    data = {k: v for k, v in good.items() if k != "slope"}
    (tmp_path / "layer.json").write_text(json.dumps(data))
    with pytest.raises(CaseFileError, match=r"layer.json: missing field\(s\): 'slope'"):
        read_layer_file(tmp_path)
    (tmp_path / "layer.json").write_text("")
    with pytest.raises(CaseFileError, match="layer.json: is empty"):
        read_layer_file(tmp_path)


def _contact_row(body_i="0", body_j="-1", force="1.0"):
    return ",".join([body_i, body_j, "0.0", "0.0", "0.0", force] + ["0.0"] * 5)


def test_bad_contact_tables_are_errors_naming_the_line_and_an_empty_table_is_not_no_contacts(
        tmp_path):
    path = tmp_path / "contacts.csv"
    header = ",".join(CONTACT_COLUMNS)
    path.write_text("# contacts\n" + header + "\n")
    assert len(read_contact_table(path).body_i) == 0          # header, no rows: no contacts
    path.write_text(header + "\n" + _contact_row() + "\n")
    assert read_contact_table(path).body_j.tolist() == [-1]
    cases = [
        ("", "contacts.csv: is empty"),
        ("# only a comment\n", "contacts.csv: has no header line"),
        (_contact_row() + "\n", "contacts.csv:1: columns"),
        (header + "\n" + _contact_row(body_i="1.7") + "\n", "contacts.csv:2: body_i = 1.7 is not an integer"),
        (header + "\n" + _contact_row(body_j="-1.5") + "\n", "contacts.csv:2: body_j = -1.5"),
        (header + "\n\n" + _contact_row(force="inf") + "\n", "contacts.csv:3: normal_force_x_N = inf"),
        (header + "\n" + _contact_row(force="nan") + "\n", "contacts.csv:2: normal_force_x_N = nan"),
        (header + "\n" + _contact_row() + ",4.0\n", "contacts.csv:2: expected 11 fields"),
        (header + "\n" + _contact_row(body_i="-1") + "\n", "contacts.csv:2: body_i = -1"),
        (header + "\n" + _contact_row(body_i="2", body_j="2") + "\n", "contacts.csv:2: body_i and body_j"),
    ]
    for text, expected in cases:
        path.write_text(text)
        with pytest.raises(CaseFileError) as error:
            read_contact_table(path)
        assert expected in str(error.value), (text, str(error.value))


@pytest.fixture()
def run_folder(tmp_path):
    """A one-cube pack and a run folder whose bodies.pvd lists a missing and a truncated frame."""
    from riprap.io.layer_file import write_contact_table
    from riprap.io.pack import PackBody, write_pack
    from riprap.solid.materials import Material
    from riprap.solid.solver import ContactRecords

    layer = _layer()
    pack = tmp_path / "pack"
    concrete = Material(name="concrete", density=2400.0, friction_coefficient=0.6,
                        restitution=0.3, contact_penalty=1e8)
    write_pack(pack, shapes={"cube": TetMesh(CUBE_NODES - 0.5, CUBE_TETS, name="cube")},
               materials=[concrete],
               bodies=[PackBody(shape="cube", material="concrete",
                                position=tuple(layer.design_positions[0]),
                                orientation=(1.0, 0.0, 0.0, 0.0))],
               walls=layer.slope.walls(face_material="concrete", side_material="concrete"))
    write_layer_file(pack, layer)
    write_contact_table(pack / "contacts.csv", ContactRecords(
        body_i=np.zeros(0, np.int64), body_j=np.zeros(0, np.int64), points=np.zeros((0, 3)),
        normal_forces=np.zeros((0, 3)), tangential_forces=np.zeros((0, 3)),
        stiffness=np.zeros(0)))
    run = tmp_path / "run"
    run.mkdir()
    write_json(run / "summary.json", {"case_file": str((pack / "pack.toml").resolve())})
    for series, stem in (("bodies.pvd", "bodies"), ("contacts.pvd", "contacts")):
        datasets = "".join(f'<DataSet timestep="{t!r}" group="" part="0" file="{stem}_{k:06d}.vtu"/>'
                           for k, t in enumerate((0.0, 0.5)))
        (run / series).write_text('<?xml version="1.0"?><VTKFile type="Collection" version="0.1">'
                                  f"<Collection>{datasets}</Collection></VTKFile>")
    good = _write_vtu(tmp_path / "frame.vtu", CUBE_NODES, [("triangle", CUBE_TETS[:, :3])])
    (run / "bodies_000001.vtu").write_bytes(good.read_bytes()[:100])   # cut off while writing
    return run


def test_run_folder_with_missing_or_truncated_frames_and_frame_out_of_range(run_folder):
    with pytest.raises(CaseFileError) as error:
        load_run_state(run_folder, frame=0)
    assert "bodies_000000.vtu" in str(error.value)
    assert "frame 0 of bodies.pvd" in str(error.value) and "does not exist" in str(error.value)
    with pytest.raises(CaseFileError) as error:
        load_run_state(run_folder, frame=1)
    assert "bodies_000001.vtu" in str(error.value) and "frame 1 of bodies.pvd" in str(error.value)
    assert "truncated" in str(error.value)
    with pytest.raises(CaseFileError, match=r"frame 5 does not exist; the run wrote 2 frames"):
        load_run_state(run_folder, frame=5)
    with pytest.raises(CaseFileError, match=r"frame must be an integer"):
        load_run_state(run_folder, frame=1.5)


def test_json_outputs_never_hold_nan_or_infinity(tmp_path):
    path = write_json(tmp_path / "summary.json", {
        "nan": math.nan, "inf": math.inf, "numpy": np.float64(-np.inf), "fine": 1.5,
        "array": np.array([1.0, np.nan, np.inf]), "nested": {"list": [math.nan, (2.0, -math.inf)]}})
    text = path.read_text()
    for token in ("NaN", "Infinity"):
        assert token not in text

    def refuse(token):
        raise AssertionError(f"non-standard JSON token {token}")

    data = json.loads(text, parse_constant=refuse)
    assert data == {"nan": None, "inf": None, "numpy": None, "fine": 1.5,
                    "array": [1.0, None, None], "nested": {"list": [None, [2.0, None]]}}



def test_a_run_folder_without_frames_is_named_not_taken_for_a_pack(tmp_path, capsys):
    """A run with [output] paraview = false wrote no bodies.pvd: riprap analyse says so (it was
    read as a pack folder without its pack.toml) and writes nothing."""
    from riprap.cli import main

    run = tmp_path / "run"
    run.mkdir()
    (run / "summary.json").write_text(json.dumps({"case_file": str(tmp_path / "case.toml")}))
    (run / "checkpoint.npz").write_bytes(b"")
    assert main(["analyse", str(run), "--out", str(tmp_path / "analysis")]) == 2
    err = capsys.readouterr().err
    assert "a run folder without bodies.pvd" in err and "paraview = true" in err
    assert not (tmp_path / "analysis").exists()
