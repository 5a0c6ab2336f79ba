"""Placement grid files (riprap.io.grid_file): format, exact round trips, errors naming file:line.

The roll/pitch/yaw check compares with R = Rz(yaw) Ry(pitch) Rx(roll) multiplied out here from
the three elementary rotations (the aerospace z-y-x convention the reader documents), independent
of scipy; tolerance 1e-12, the rounding of sin/cos and a product of three rotations.
"""
import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.io.grid_file import GridPoints, read_grid_file, write_grid_file

# Rotations built from angles in degrees carry rounding of sin/cos and three products.
ROTATION_TOLERANCE = 1e-12


def _write(tmp_path, text, name="grid.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _error(tmp_path, text, name="grid.csv"):
    path = _write(tmp_path, text, name)
    with pytest.raises(CaseFileError) as caught:
        read_grid_file(path)
    return str(caught.value), caught.value, str(path)


def _matrix(quaternion):
    w, x, y, z = quaternion
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def _rpy_matrix(roll, pitch, yaw):
    r, p, y = np.radians([roll, pitch, yaw])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    return rz @ ry @ rx


# ---------------------------------------------------------------------------------- reading


def test_read_grid_positions_lines_and_comments(tmp_path):
    path = _write(tmp_path, "# design grid\n\n  X , y,Z  \n0, 0, 0.1\n# a comment\n\n"
                            "0.25, -1e-3, 1.5\n")
    grid = read_grid_file(path)
    assert isinstance(grid, GridPoints)
    assert grid.positions.tolist() == [[0.0, 0.0, 0.1], [0.25, -1e-3, 1.5]]
    assert grid.lines.tolist() == [4, 7]
    assert grid.orientations is None and grid.velocities is None
    assert len(grid) == 2
    assert grid.where(1) == f"{path}:7"
    with pytest.raises(ValueError):
        grid.positions[0, 0] = 1.0


def test_read_grid_quaternions_are_normalised_and_velocities_read(tmp_path):
    path = _write(tmp_path, "x,y,z,qw,qx,qy,qz,vx,vy,vz\n0,0,0, 2,0,0,0, 0.1,0,-0.2\n"
                            "1,0,0, 1,1,1,1, 0,0,0\n")
    grid = read_grid_file(path)
    assert np.array_equal(grid.orientations[0], [1.0, 0.0, 0.0, 0.0])
    assert np.abs(grid.orientations[1] - 0.5).max() < 1e-15
    assert grid.velocities.tolist() == [[0.1, 0.0, -0.2], [0.0, 0.0, 0.0]]


@pytest.mark.parametrize("roll, pitch, yaw", [(0, 0, 90), (30, 0, 0), (0, -45, 0),
                                              (10, 20, 30), (-170, 80, 250)])
def test_read_grid_roll_pitch_yaw_is_intrinsic_zyx(tmp_path, roll, pitch, yaw):
    path = _write(tmp_path, f"x, y, z, roll, pitch, yaw\n0, 0, 0, {roll}, {pitch}, {yaw}\n")
    quaternion = read_grid_file(path).orientations[0]
    assert abs(np.linalg.norm(quaternion) - 1.0) < ROTATION_TOLERANCE
    assert np.abs(_matrix(quaternion) - _rpy_matrix(roll, pitch, yaw)).max() < ROTATION_TOLERANCE


def test_read_grid_yaw_90_turns_x_axis_to_y(tmp_path):
    path = _write(tmp_path, "x,y,z,roll,pitch,yaw\n0,0,0,0,0,90\n")
    turned = _matrix(read_grid_file(path).orientations[0]) @ [1.0, 0.0, 0.0]
    assert np.abs(turned - [0.0, 1.0, 0.0]).max() < ROTATION_TOLERANCE


# ---------------------------------------------------------------------------------- round trips


def test_grid_round_trip_positions_only_is_exact(tmp_path):
    rng = np.random.default_rng(3)
    positions = rng.normal(size=(50, 3)) * np.array([1e-3, 10.0, 1e5])
    path = write_grid_file(tmp_path / "g.csv", positions)
    grid = read_grid_file(path)
    assert np.array_equal(grid.positions, positions)
    assert grid.orientations is None and grid.velocities is None
    assert grid.lines.tolist() == list(range(3, 53))


def test_grid_round_trip_with_orientations_and_velocities_is_exact(tmp_path):
    rng = np.random.default_rng(4)
    positions = rng.uniform(-1, 1, size=(40, 3))
    orientations = rng.normal(size=(40, 4))
    orientations /= np.linalg.norm(orientations, axis=1)[:, None]
    velocities = rng.normal(size=(40, 3)) * 1e-7
    path = write_grid_file(tmp_path / "g.csv", positions, orientations, velocities)
    grid = read_grid_file(path)
    assert np.array_equal(grid.positions, positions)
    assert np.array_equal(grid.orientations, orientations)
    assert np.array_equal(grid.velocities, velocities)


def test_grid_written_file_can_be_edited_and_read(tmp_path):
    path = write_grid_file(tmp_path / "g.csv", [[0.0, 0.0, 0.1], [0.2, 0.0, 0.1]])
    text = path.read_text().replace("0.2, 0.0, 0.1", "0.2, 0.0, 0.1\n# added by hand\n0.4, 0, 0.1")
    path.write_text(text)
    grid = read_grid_file(path)
    assert grid.positions[:, 0].tolist() == [0.0, 0.2, 0.4]
    assert grid.lines.tolist() == [3, 4, 6]


@pytest.mark.parametrize("arguments, words", [
    (([[0.0, 0.0]],), "positions must have shape (n, 3)"),
    ((np.zeros((0, 3)),), "positions has no rows"),
    (([[0.0, np.nan, 0.0]],), "positions row 0"),
    (([[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0, 0.0]]), "norm 0"),
    (([[0.0, 0.0, 0.0]], [[1.0, 0.0, 0.0, 0.0]] * 2), "orientations has 2 rows"),
    (([[0.0, 0.0, 0.0]], None, [[0.0, np.inf, 0.0]]), "velocities row 0"),
])
def test_write_grid_file_rejects_bad_arrays(tmp_path, arguments, words):
    with pytest.raises(CaseFileError, match="write_grid_file") as caught:
        write_grid_file(tmp_path / "g.csv", *arguments)
    assert words in str(caught.value)


# ---------------------------------------------------------------------------------- errors


@pytest.mark.parametrize("text, line, words", [
    ("x,y,z\n0,0,0\n1,abc,0\n", 3, "column 'y' = 'abc': not a number"),
    ("x,y,z\n0,0,nan\n", 2, "column 'z' = nan: not a finite number"),
    ("x,y,z\n0,0,-inf\n", 2, "column 'z' = -inf: not a finite number"),
    ("x,y,z\n0,0,0\n0,0\n", 3, "2 field(s), expected 3 (x, y, z)"),
    ("x,y,z\n0,0,0,7\n", 2, "4 field(s), expected 3"),
    ("# c\nx,y\n0,0\n", 2, "missing required column(s) z"),
    ("x,y,z,x\n0,0,0,0\n", 1, "duplicate column 'x' (fields 1 and 4)"),
    ("x,y,z, YW\n0,0,0,0\n", 1, "unknown column 'yw'; did you mean 'yaw'?"),
    ("x,y,z,,\n0,0,0,,\n", 1, "header field 4 is empty"),
    ("x,y,z,qw,qx,qy\n0,0,0,1,0,0\n", 1, "qw, qx, qy given without qz"),
    ("x,y,z,vx\n0,0,0,1\n", 1, "vx given without vy, vz"),
    ("x,y,z,pitch,yaw\n0,0,0,1,2\n", 1, "pitch, yaw given without roll"),
    ("x,y,z,qw,qx,qy,qz,roll,pitch,yaw\n0,0,0,1,0,0,0,0,0,0\n", 1, "both quaternion"),
    ("x,y,z,qw,qx,qy,qz\n0,0,0,1,0,0,0\n0,0,0,1e-7,0,0,0\n", 3,
     "quaternion (qw, qx, qy, qz) = (1e-07, 0.0, 0.0, 0.0) has norm 1e-07"),
    ("x;y;z\n0;0;0\n", 1, "separated by commas"),
    ("", 1, "empty grid file"),
    ("# only\n# comments\n\n", 3, "empty grid file"),
    ("# header only\nx, y, z\n\n", 2, "no data rows"),
])
def test_read_grid_errors_name_file_line_column_and_value(tmp_path, text, line, words):
    message, _, path = _error(tmp_path, text)
    assert message.startswith(f"{path}:{line}: "), message
    assert words in message


def test_read_grid_reports_every_bad_line_at_once(tmp_path):
    message, error, path = _error(tmp_path, "x,y,z\n0,0,0\n0,zero,0\n1,1,1\n0,0\n2,2,inf\n")
    lines = message.splitlines()
    assert lines == [f"{path}:3: column 'y' = 'zero': not a number",
                     f"{path}:5: 2 field(s), expected 3 (x, y, z)",
                     f"{path}:6: column 'z' = inf: not a finite number"]
    assert len(error.problems) == 3


def test_read_grid_lists_twenty_problems_then_a_count(tmp_path):
    text = "x,y,z\n" + "".join(f"{k},bad,0\n" for k in range(25))
    message, error, path = _error(tmp_path, text)
    lines = message.splitlines()
    assert len(lines) == 21
    assert lines[0].startswith(f"{path}:2: ")
    assert lines[19].startswith(f"{path}:21: ")
    assert lines[20] == "... and 5 more problem(s) not shown; fix the ones above first"
    assert len(error.problems) == 25


def test_read_grid_header_problems_reported_together(tmp_path):
    message, error, path = _error(tmp_path, "x, y, qw, speed\n0,0,1,0\n")
    assert f"{path}:1: unknown column 'speed'" in message
    assert f"{path}:1: missing required column(s) z" in message
    assert f"{path}:1: column(s) qw given without qx, qy, qz" in message
    assert len(error.problems) == 3


def test_read_grid_missing_file_names_it(tmp_path):
    with pytest.raises(CaseFileError, match="grid file not found") as caught:
        read_grid_file(tmp_path / "nowhere.csv")
    assert "nowhere.csv" in str(caught.value)


def test_read_grid_non_utf8_names_line(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes(b"x,y,z\n0,0,0\n# caf\xe9\n")
    with pytest.raises(CaseFileError, match=r"latin\.csv:3: the grid file is not UTF-8"):
        read_grid_file(path)
