"""Checkpoints: bit-exact round trips, atomic replacement, and named errors on bad files."""

import numpy as np
import pytest

from riprap.errors import CaseFileError, RiprapError
from riprap.io.checkpoint import (
    save_checkpoint_piece,
    CHECKPOINT_FORMAT,
    CheckpointError,
    load_checkpoint,
    save_checkpoint,
)


def _example_arrays():
    rng = np.random.default_rng(3)
    return {
        "positions": rng.normal(size=(5, 3)),
        "quaternions": rng.normal(size=(5, 4)).astype(np.float32),
        "tets": rng.integers(0, 100, size=(7, 4)).astype(np.int32),
        "body_of_node": np.arange(11, dtype=np.int64),
        "in_contact": rng.random(9) > 0.5,
        "special_values": np.array([np.nan, np.inf, -np.inf, -0.0, 5e-324]),
        "step": np.array(12345, dtype=np.uint64),
        "empty": np.zeros((0, 3)),
    }


def test_checkpoint_round_trip_is_bit_exact(tmp_path):
    arrays = _example_arrays()
    metadata = {"time": 0.1 + 0.2, "step": 42, "case_file": "case.toml", "bodies": [1, 2]}
    path = save_checkpoint(tmp_path / "state.npz", arrays=arrays, metadata=metadata)
    loaded, loaded_metadata = load_checkpoint(path)

    assert set(loaded) == set(arrays)
    for name, array in arrays.items():
        assert loaded[name].dtype == array.dtype, name
        assert loaded[name].shape == array.shape, name
        # Compare raw bytes: NaN payloads and the sign of zero must survive too.
        assert loaded[name].tobytes() == np.ascontiguousarray(array).tobytes(), name
    assert loaded_metadata == {**metadata, "checkpoint_format": CHECKPOINT_FORMAT}


def test_checkpoint_metadata_accepts_numpy_scalars(tmp_path):
    path = save_checkpoint(tmp_path / "state.npz", arrays={},
                           metadata={"time": np.float64(0.25), "step": np.int64(7)})
    _, metadata = load_checkpoint(path)
    assert metadata["time"] == 0.25 and metadata["step"] == 7


def test_checkpoint_overwrite_replaces_previous_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "state.npz"
    save_checkpoint(path, arrays={"x": np.zeros(3)}, metadata={"step": 1})
    save_checkpoint(path, arrays={"x": np.ones(3)}, metadata={"step": 2})
    arrays, metadata = load_checkpoint(path)
    assert metadata["step"] == 2
    assert np.array_equal(arrays["x"], np.ones(3))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["state.npz"]


def test_checkpoint_failed_write_keeps_previous_file(tmp_path):
    path = tmp_path / "state.npz"
    save_checkpoint(path, arrays={"x": np.arange(4)}, metadata={"step": 1})
    before = path.read_bytes()
    with pytest.raises(CaseFileError, match="metadata"):
        save_checkpoint(path, arrays={"x": np.arange(5)}, metadata={"bad": object()})
    with pytest.raises(CaseFileError, match="object"):
        save_checkpoint(path, arrays={"x": np.array([None, 1])}, metadata={})
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["state.npz"]


def test_checkpoint_reserved_array_name_is_refused(tmp_path):
    with pytest.raises(CaseFileError, match="reserved"):
        save_checkpoint(tmp_path / "s.npz", arrays={"__riprap_metadata__": np.zeros(1)},
                        metadata={})


def test_missing_checkpoint_raises_named_error(tmp_path):
    path = tmp_path / "nowhere.npz"
    with pytest.raises(CheckpointError, match="nowhere.npz"):
        load_checkpoint(path)


@pytest.mark.parametrize("kept_fraction", [0.0, 0.3, 0.7, 0.95])
def test_truncated_checkpoint_raises_named_error(tmp_path, kept_fraction):
    path = tmp_path / "state.npz"
    save_checkpoint(path, arrays=_example_arrays(), metadata={"step": 3})
    data = path.read_bytes()
    path.write_bytes(data[: int(kept_fraction * len(data))])
    with pytest.raises(CheckpointError, match="state.npz") as caught:
        load_checkpoint(path)
    assert isinstance(caught.value, RiprapError)


def test_corrupted_checkpoint_bytes_raise_named_error(tmp_path):
    path = tmp_path / "state.npz"
    save_checkpoint(path, arrays={"positions": np.arange(4000, dtype=np.float64)}, metadata={})
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle: middle + 64] = bytes(64)
    path.write_bytes(bytes(data))
    with pytest.raises(CheckpointError, match="corrupt"):
        load_checkpoint(path)


def test_foreign_npz_is_not_a_checkpoint(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, x=np.zeros(2))
    with pytest.raises(CheckpointError, match="not a riprap checkpoint"):
        load_checkpoint(path)


def test_plain_text_file_is_not_a_checkpoint(tmp_path):
    path = tmp_path / "notes.npz"
    path.write_text("hello")
    with pytest.raises(CheckpointError, match="notes.npz is not a riprap checkpoint"):
        load_checkpoint(path)


def test_other_checkpoint_format_version_is_refused(tmp_path):
    path = tmp_path / "future.npz"
    save_checkpoint(path, arrays={"x": np.zeros(1)}, metadata={})
    # Rewrite the metadata entry as a future riprap would.
    with np.load(path) as archive:
        contents = {name: archive[name] for name in archive.files}
    contents["__riprap_metadata__"] = np.array('{"checkpoint_format": 2}')
    np.savez(path, **contents)
    with pytest.raises(CheckpointError, match="checkpoint_format 2"):
        load_checkpoint(path)


# ---------------------------------------------------------------- checkpoints in pieces
def _pieces(tmp_path, step=7, processes=3):
    """A checkpoint of a run over ``processes``: each process's planes of a (6, 2) grid array
    and of a (7,) x-face array (the last process its top face too), and a shared clock."""
    path = tmp_path / "checkpoint.npz"
    grid, faces = np.arange(12.0).reshape(6, 2), np.arange(7.0) * 0.5
    cuts = np.linspace(0, 6, processes + 1).astype(int)
    names = [save_checkpoint_piece(path, step=step, process=p, arrays={
        "grid": grid[cuts[p]:cuts[p + 1]],
        "faces": faces[cuts[p]:cuts[p + 1] + (1 if p == processes - 1 else 0)]})
        for p in range(processes)]
    save_checkpoint(path, arrays={"clock": np.array([0.5, float(step)])},
                    metadata={"time": 0.5}, pieces=names)
    return path, grid, faces, names


def test_checkpoint_in_pieces_reads_back_whole(tmp_path):
    """The pieces' arrays are joined in process order: the whole arrays, bit for bit; the
    list of pieces is not part of what is read."""
    path, grid, faces, names = _pieces(tmp_path)
    arrays, metadata = load_checkpoint(path)
    assert np.array_equal(arrays["grid"], grid) and np.array_equal(arrays["faces"], faces)
    assert "pieces" not in metadata
    assert names[1] == "checkpoint_pieces/step000000007_process0001.npz"


def test_checkpoint_pieces_of_earlier_writes_are_removed(tmp_path):
    """A later checkpoint in pieces removes the earlier's pieces once it is in place; a whole
    checkpoint written over it (a restart on one process) removes them all."""
    path, *_ = _pieces(tmp_path, step=7)
    _pieces(tmp_path, step=9)
    assert sorted(p.name for p in (tmp_path / "checkpoint_pieces").iterdir()) == [
        f"step000000009_process000{k}.npz" for k in range(3)]
    save_checkpoint(path, arrays={"grid": np.zeros((6, 2))}, metadata={})
    assert not (tmp_path / "checkpoint_pieces").exists()
    assert load_checkpoint(path)[0]["grid"].shape == (6, 2)


def test_checkpoint_missing_or_foreign_piece_is_named(tmp_path):
    """A missing piece, a piece of another step put in its place, a piece given as the
    checkpoint, a piece of another process: each refused with a message naming it."""
    path, _, _, names = _pieces(tmp_path)
    piece = tmp_path / names[2]
    kept = piece.read_bytes()
    piece.unlink()
    with pytest.raises(CheckpointError, match=r"piece checkpoint_pieces/step000000007_process0002"
                                              r"\.npz \(process 2\) is missing"):
        load_checkpoint(path)
    save_checkpoint_piece(path, step=8, process=2, arrays={"grid": np.zeros((2, 2)),
                                                          "faces": np.zeros(3)})
    (tmp_path / "checkpoint_pieces" / "step000000008_process0002.npz").rename(piece)
    with pytest.raises(CheckpointError, match="is of step 8, the checkpoint of step 7"):
        load_checkpoint(path)
    piece.write_bytes(kept)
    with pytest.raises(CheckpointError, match="one process's piece of the checkpoint "
                                              "checkpoint.npz"):
        load_checkpoint(piece)
    (tmp_path / names[1]).write_bytes(kept)
    with pytest.raises(CheckpointError, match="is not the piece of process 1"):
        load_checkpoint(path)


def test_a_process_reads_only_the_pieces_holding_its_planes(tmp_path):
    """With ``planes``, the grid's arrays come from the pieces that hold those planes alone,
    whole-shaped with zeros elsewhere; other arrays (and every piece's step) are read as before.
    Shown by damaging the data of the piece of planes 4-5, which a read of planes 0-2 never
    opens, and which a whole read refuses."""
    path, grid, faces, names = _pieces(tmp_path)          # 3 pieces of 2 planes each
    far = tmp_path / names[2]
    arrays, _ = load_checkpoint(far, piece=True)
    save_checkpoint(far, arrays={"grid": arrays["grid"], "faces": arrays["faces"]},
                    metadata={"piece_of": path.name, "step": 7, "process": 2})
    import zipfile
    damaged = tmp_path / "damaged.npz"
    with zipfile.ZipFile(far) as source, zipfile.ZipFile(damaged, "w") as target:
        for item in source.infolist():
            data = source.read(item)
            target.writestr(item, data[:-8] if item.filename == "grid.npy" else data)
    damaged.replace(far)
    arrays, _ = load_checkpoint(path, planes=(0, 3), plane_arrays=("grid",))
    assert arrays["grid"].shape == grid.shape
    assert np.array_equal(arrays["grid"][:4], grid[:4])      # the pieces of planes 0-1 and 2-3
    assert not arrays["grid"][4:].any()
    assert np.array_equal(arrays["faces"], faces)            # not a plane array: every piece
    with pytest.raises(CheckpointError, match="grid is truncated or corrupt"):
        load_checkpoint(path)
    with pytest.raises(CheckpointError, match="grid is truncated or corrupt"):
        load_checkpoint(path, planes=(3, 5), plane_arrays=("grid",))
