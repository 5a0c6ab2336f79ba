"""Frames of a run over several processes: ParaView's parallel image data (``.pvti``) naming one
``.vti`` piece per process (``riprap/io/vti.py``), listed in the ``.pvd`` and trimmed on restart
(``riprap/io/vtk.py``). Checked against the same fields written whole."""
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.io.vti import read_pvti, read_vti, write_pvti, write_vti
from riprap.io.vtk import ParaViewSeries


def _fields(cells):
    rng = np.random.default_rng(5)
    return {"water_fraction": rng.random(cells), "velocity": rng.normal(size=cells + (3,))}


def _write_in_pieces(directory, stem, fields, cuts, origin=(-1.0, 0.5, 0.0), h=0.25):
    cells = fields["water_fraction"].shape
    pieces = []
    for k, (first, stop) in enumerate(zip(cuts[:-1], cuts[1:])):
        name = f"{stem}/piece_{k:04d}.vti"
        write_vti(directory / name, origin=origin, spacing=h, cells=(stop - first,) + cells[1:],
                  cell_data={key: value[first:stop] for key, value in fields.items()},
                  start=(first, 0, 0))
        pieces.append((name, first, stop))
    return write_pvti(directory / f"{stem}.pvti", origin=origin, spacing=h, cells=cells,
                      fields={"water_fraction": 1, "velocity": 3}, pieces=pieces)


def test_pieces_join_to_the_whole_frame(tmp_path):
    """Three pieces of a (10, 3, 4) grid read back as the whole grid written in one file,
    bit for bit (float32); each piece's extent is its place in the whole grid."""
    fields = _fields((10, 3, 4))
    write_vti(tmp_path / "whole.vti", origin=(-1.0, 0.5, 0.0), spacing=0.25, cells=(10, 3, 4),
              cell_data=fields)
    path = _write_in_pieces(tmp_path, "frame", fields, [0, 3, 7, 10])
    whole, joined = read_vti(tmp_path / "whole.vti"), read_pvti(path)
    assert all(np.array_equal(whole[name], joined[name]) for name in whole)
    assert joined["velocity"].shape == (10, 3, 4, 3)
    assert 'Extent="3 7 0 3 0 4" Source="frame/piece_0001.vti"' in path.read_text()
    assert 'WholeExtent="3 7 0 3 0 4"' in (tmp_path / "frame" / "piece_0001.vti").read_text(
        errors="replace")


def test_pieces_that_do_not_cover_the_grid_or_are_missing_are_named(tmp_path):
    fields = _fields((10, 3, 4))
    with pytest.raises(CaseFileError, match=r"do not cover 0 \.\. 10"):
        _write_in_pieces(tmp_path, "gap", fields, [0, 3, 9])
    path = _write_in_pieces(tmp_path, "frame", fields, [0, 5, 10])
    (tmp_path / "frame" / "piece_0001.vti").unlink()
    with pytest.raises(CaseFileError, match=r"piece frame/piece_0001\.vti \(x-cells 5 \.\. 10\) "
                                            "is missing"):
        read_pvti(path)


def test_series_of_pieces_is_trimmed_on_restart(tmp_path):
    """A ``.pvd`` of ``.pvti`` frames continued after a restart at t = 0.1: the frames after it
    are dropped from the list, their ``.pvti`` and their folders of pieces deleted, and the
    numbering goes on after the frames kept."""
    fields = _fields((4, 1, 2))
    series = ParaViewSeries(tmp_path, "fluid")
    for time in (0.0, 0.1, 0.2):
        stem = series.next_frame_stem(time)
        _write_in_pieces(tmp_path, stem, fields, [0, 2, 4])
        series.list_frame(time, f"{stem}.pvti")
    assert series.frames[-1] == (0.2, "fluid_000002.pvti")
    again = ParaViewSeries(tmp_path, "fluid", append=True)
    assert again.next_frame_stem(0.15) == "fluid_000002"
    assert not (tmp_path / "fluid_000002.pvti").exists()
    assert not (tmp_path / "fluid_000002").exists() and (tmp_path / "fluid_000001").is_dir()
    with pytest.raises(CaseFileError, match="not after the last frame's time"):
        again.list_frame(0.1, "fluid_000002.pvti")
