"""ParaView output: .vtu round trips through meshio, .pvd series and restart in append mode."""

import xml.etree.ElementTree as ElementTree

import meshio
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.io.checkpoint import CheckpointError
from riprap.io.vtk import ParaViewSeries, write_contacts_vtu, write_vtu


def _two_tets():
    points = np.array(
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]
    )
    cells = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
    return points, cells


def _pvd_frames(path):
    """(timestep, file) of each DataSet, parsed independently of ParaViewSeries."""
    root = ElementTree.parse(path).getroot()
    assert root.tag == "VTKFile" and root.attrib["type"] == "Collection"
    (collection,) = list(root)
    assert collection.tag == "Collection"
    return [(float(d.attrib["timestep"]), d.attrib["file"]) for d in collection]


def test_write_vtu_round_trips_points_cells_and_data(tmp_path):
    points, cells = _two_tets()
    velocities = np.arange(15, dtype=np.float64).reshape(5, 3) / 7.0
    body = np.array([3, 9], dtype=np.int64)
    at_rest = np.array([True, False])
    path = tmp_path / "bodies.vtu"
    write_vtu(path, points=points, cells=cells,
              point_data={"velocity": velocities, "speed": np.linalg.norm(velocities, axis=1)},
              cell_data={"body": body, "at_rest": at_rest})

    mesh = meshio.read(path)
    # Binary VTU stores float64 exactly, so equality is exact.
    assert np.array_equal(mesh.points, points)
    assert len(mesh.cells) == 1 and mesh.cells[0].type == "tetra"
    assert np.array_equal(mesh.cells[0].data, cells)
    assert np.array_equal(mesh.point_data["velocity"], velocities)
    assert np.array_equal(mesh.cell_data["body"][0], body)
    assert np.array_equal(mesh.cell_data["at_rest"][0], at_rest.astype(np.uint8))
    text = path.read_bytes()
    assert b'compressor="vtkZLibDataCompressor"' in text and b'format="binary"' in text
    assert [p.name for p in tmp_path.iterdir()] == ["bodies.vtu"]


def test_write_vtu_triangles(tmp_path):
    points, _ = _two_tets()
    triangles = np.array([[0, 1, 2], [1, 2, 4]])
    write_vtu(tmp_path / "surface.vtu", points=points, cells=triangles, cell_type="triangle")
    mesh = meshio.read(tmp_path / "surface.vtu")
    assert mesh.cells[0].type == "triangle"
    assert np.array_equal(mesh.cells[0].data, triangles)


@pytest.mark.parametrize(
    "change, message",
    [
        ({"cells": np.array([[0, 1, 2, 5]])}, "point indices"),
        ({"cells": np.array([[0, 1, 2]])}, "cells have shape"),
        ({"cell_type": "hexahedron"}, "cell_type"),
        ({"points": np.zeros((5, 2))}, "points have shape"),
        ({"point_data": {"speed": np.zeros(4)}}, "speed"),
    ],
)
def test_write_vtu_rejects_wrong_input_with_named_error(tmp_path, change, message):
    points, cells = _two_tets()
    arguments = {"points": points, "cells": cells, **change}
    with pytest.raises(CaseFileError, match=message):
        write_vtu(tmp_path / "bad.vtu", **arguments)
    assert not list(tmp_path.iterdir())


def test_write_contacts_vtu_has_vertex_cells_and_force_vectors(tmp_path):
    rng = np.random.default_rng(0)
    points = rng.random((6, 3))
    normal = rng.normal(size=(6, 3))
    tangential = rng.normal(size=(6, 3))
    body_i, body_j = np.arange(6), np.arange(6) + 10
    path = tmp_path / "contacts.vtu"
    write_contacts_vtu(path, points=points, normal_forces=normal, tangential_forces=tangential,
                       body_i=body_i, body_j=body_j)
    mesh = meshio.read(path)
    assert mesh.cells[0].type == "vertex"
    assert np.array_equal(mesh.cells[0].data.ravel(), np.arange(6))
    assert np.array_equal(mesh.point_data["normal_force"], normal)
    assert np.array_equal(mesh.point_data["tangential_force"], tangential)
    assert np.array_equal(mesh.point_data["body_j"], body_j)
    assert np.issubdtype(mesh.point_data["body_i"].dtype, np.integer)
    # Same numpy call on the same float64 data, stored exactly: equal to the last bit.
    assert np.array_equal(mesh.point_data["normal_force_magnitude"],
                          np.linalg.norm(normal, axis=1))


def test_write_contacts_vtu_with_no_contacts_writes_an_empty_grid(tmp_path):
    path = tmp_path / "contacts.vtu"
    empty = np.zeros((0, 3))
    write_contacts_vtu(path, points=empty, normal_forces=empty, tangential_forces=empty,
                       body_i=np.zeros(0, int), body_j=np.zeros(0, int))
    piece = ElementTree.parse(path).getroot().find("UnstructuredGrid/Piece")
    assert piece.attrib["NumberOfPoints"] == "0" and piece.attrib["NumberOfCells"] == "0"


def test_series_pvd_lists_exactly_the_frames_written(tmp_path):
    points, cells = _two_tets()
    series = ParaViewSeries(tmp_path / "vtk", name="bodies")
    times = [0.0, 0.05, 0.1, 0.1 + 0.05]
    for k, time in enumerate(times):
        path = series.add(time, points=points + k, cells=cells, cell_data={"body": np.arange(2)})
        assert path.name == f"bodies_{k:06d}.vtu"
        # After every frame the index is complete and valid: a kill here loses nothing listed.
        assert _pvd_frames(series.pvd_path) == series.frames

    expected = [(time, f"bodies_{k:06d}.vtu") for k, time in enumerate(times)]
    assert series.frames == expected
    assert _pvd_frames(tmp_path / "vtk" / "bodies.pvd") == expected
    for k, (_, file_name) in enumerate(expected):
        assert np.array_equal(meshio.read(tmp_path / "vtk" / file_name).points, points + k)
    assert sorted(p.name for p in (tmp_path / "vtk").iterdir()) == sorted(
        ["bodies.pvd"] + [name for _, name in expected]
    )


def test_series_refuses_time_going_backwards(tmp_path):
    points, cells = _two_tets()
    series = ParaViewSeries(tmp_path)
    series.add(1.0, points=points, cells=cells)
    with pytest.raises(CaseFileError, match="append=True"):
        series.add(1.0, points=points, cells=cells)
    assert series.frames == [(1.0, "bodies_000000.vtu")]


def test_series_append_after_restart_drops_later_frames_and_continues(tmp_path):
    points, cells = _two_tets()
    first_run = ParaViewSeries(tmp_path, name="bodies")
    for time in (0.0, 0.1, 0.2, 0.3, 0.4):
        first_run.add(time, points=points, cells=cells)
    del first_run  # the run is killed; the restart checkpoint is at t = 0.2 s

    restarted = ParaViewSeries(tmp_path, name="bodies", append=True)
    assert [time for time, _ in restarted.frames] == [0.0, 0.1, 0.2, 0.3, 0.4]
    restarted.add(0.2, points=points + 1.0, cells=cells)
    restarted.add(0.3, points=points + 2.0, cells=cells)

    expected = [
        (0.0, "bodies_000000.vtu"),
        (0.1, "bodies_000001.vtu"),
        (0.2, "bodies_000002.vtu"),
        (0.3, "bodies_000003.vtu"),
    ]
    assert restarted.frames == expected
    assert _pvd_frames(tmp_path / "bodies.pvd") == expected
    assert np.array_equal(meshio.read(tmp_path / "bodies_000002.vtu").points, points + 1.0)
    assert np.array_equal(meshio.read(tmp_path / "bodies_000003.vtu").points, points + 2.0)
    # The frame at 0.4 s belonged to the abandoned run and is gone with its file.
    assert not (tmp_path / "bodies_000004.vtu").exists()


def test_series_append_without_existing_pvd_starts_fresh(tmp_path):
    points, cells = _two_tets()
    series = ParaViewSeries(tmp_path / "new", append=True)
    series.add(0.5, points=points, cells=cells)
    assert _pvd_frames(tmp_path / "new" / "bodies.pvd") == [(0.5, "bodies_000000.vtu")]


def test_series_without_append_replaces_an_old_index(tmp_path):
    points, cells = _two_tets()
    ParaViewSeries(tmp_path).add(0.0, points=points, cells=cells)
    ParaViewSeries(tmp_path)
    assert _pvd_frames(tmp_path / "bodies.pvd") == []


def test_series_append_to_corrupt_pvd_raises_named_error(tmp_path):
    (tmp_path / "bodies.pvd").write_text("<VTKFile type='Collection'><Collection>")
    with pytest.raises(CheckpointError, match="bodies.pvd"):
        ParaViewSeries(tmp_path, append=True)
