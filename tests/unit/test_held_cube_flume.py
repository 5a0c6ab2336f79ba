"""The held-cube flume of bench/unit_loads.py --flume (riprap.benchmarks.held_cube_flume): its case
loads and builds, the slope fills its wedge, and the cube sits square on the slope, 2 mm off it."""
import math
import warnings

import numpy as np

from riprap.benchmarks import held_cube_flume as flume
from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case


def test_the_cube_sits_square_on_the_slope_off_it_by_the_gap(tmp_path):
    case = load_case(flume.held_cube_case(tmp_path, 3.0, 0.005, "own_velocity"))
    assert case.fluid.cut_faces == "own_velocity"
    assert case.fluid.max_time_step == 0.005
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # the fixed cube spans 3 cells: riprap warns of it
        simulation = build_fluid_run(case, output_directory=tmp_path / "out", progress=False)
    solids = simulation.model.solver.solids
    assert solids.fixed.all() and solids.n_bodies == 2
    # the wedge: its section is a trapezoid (toe 3 m, crest 0.75 m at 1:1.5, to x = 4.2 m); the
    # mesher keeps the toe and rounds the crest's 34-degree edge a little (feature angle 40)
    section = 0.5 * (flume.LENGTH - flume.TOE + flume.LENGTH - flume.TOE
                     - flume.COTANGENT * flume.CREST) * flume.CREST
    assert abs(solids.shapes[0].volume / (section * flume.WIDTH) - 1.0) < 0.01
    # every node of the cube lies at least the gap above the slope's plane, a whole face's (its
    # four corners at least) at it: square on the slope
    s = solids.shape_index[flume.CUBE]
    table = solids.table
    nodes = (table.nodes[table.node_offset[s]:table.node_offset[s + 1]]
             @ solids.rotation_matrices()[flume.CUBE].T + solids.positions[flume.CUBE])
    angle = math.atan(1.0 / flume.COTANGENT)
    normal = np.array([-math.sin(angle), 0.0, math.cos(angle)])
    height = (nodes - np.array([flume.TOE, 0.0, 0.0])) @ normal
    assert abs(height.min() - flume.GAP) < 1e-8
    assert np.sum(np.abs(height - flume.GAP) < 1e-8) >= 4
    assert abs(height.max() - flume.GAP - flume.DN) < 1e-8
