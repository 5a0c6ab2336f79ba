"""A cube held on the slope of a short regular-wave flume: the fluid's load on one armour unit
under waves, for comparing time steps and resolutions (``bench/unit_loads.py --flume``; issue 51).

The flume: water 0.4 m deep over a flat bed, regular waves (stream function, H = 0.12 m,
T = 1.4 s, L = 2.4 m) made in a relaxation zone one wave length long at x = 0, an impermeable
1:1.5 slope from its toe at x = 3 m up to a crest at 0.75 m, nothing absorbing at the far end (the
slope ends the flume, as in a laboratory). The flume is 2 Dn wide with free-slip sides, so the cube
stands for a row of units 2 Dn apart. The cube (Dn = 0.1 m, concrete) sits square on the slope
with its centre's foot 5 cm below the still water level, held fixed 2 mm off the slope (no
contact), where run-up and run-down load it both ways. The slope is a fixed body (a wedge) so that
its face is cut exactly at every resolution.

``held_cube_case(folder, cells_per_dn, max_time_step, cut_faces)`` writes the case file and the
wedge's surface into ``folder`` and returns the case file's path; ``CUBE`` is the cube's body
index (the wedge is body 0).
"""
from __future__ import annotations

import math
from pathlib import Path

from riprap.geometry.mass_properties import mass_properties
from riprap.io.mesh_files import read_mesh

__all__ = ["held_cube_case", "CUBE", "DN", "PERIOD", "RECORD_FROM", "RECORD_PERIODS"]

DN = 0.1                  # m, the cube's side
DEPTH = 0.4               # m, still water
HEIGHT, PERIOD = 0.12, 1.4
TOE, CREST = 3.0, 0.75    # m: the slope's toe (x) and crest level (z)
COTANGENT = 1.5
LENGTH, WIDTH, TOP = 4.2, 2 * DN, 0.8
GAP = 0.002               # m between the cube and the slope
FOOT_BELOW_SWL = 0.05     # m: where the normal through the cube's centre meets the slope
RECORD_FROM = 3.0 * PERIOD    # s: ramp (2 periods) and the first wave's travel to the slope
RECORD_PERIODS = 10
CUBE = 1
WEDGE_MESH_SIZE = 0.5


def _wedge_obj() -> str:
    """The slope as a closed prism: its x-z section (toe, crest's front, crest's back, bed's
    end) extruded over the flume's width, triangles facing outward."""
    x_crest = TOE + COTANGENT * CREST
    section = [(TOE, 0.0), (LENGTH, 0.0), (LENGTH, CREST), (x_crest, CREST)]   # counter-clockwise in x-z seen from -y
    vertices = [(x, 0.0, z) for x, z in section] + [(x, WIDTH, z) for x, z in section]
    faces = [(1, 2, 3), (1, 3, 4),                 # y = 0 side (outward -y)
             (5, 7, 6), (5, 8, 7)]                 # y = W side (outward +y)
    for a in range(4):
        b = (a + 1) % 4
        faces += [(a + 1, b + 5, b + 1), (a + 1, a + 5, b + 5)]
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices]
    lines += [f"f {i} {j} {k}" for i, j, k in faces]
    return "\n".join(lines) + "\n"


def held_cube_case(folder, cells_per_dn: float, max_time_step: float,
                   cut_faces: str = "own_velocity") -> Path:
    """Write the flume's case (and ``slope.obj``) into ``folder``; return the case's path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "slope.obj").write_text(_wedge_obj())
    # placed by the centroid riprap finds for the meshed wedge (its tet mesh's, within mm of the
    # prism's own), so that the wedge ends flush with the bed and the box's end
    wedge = mass_properties(read_mesh(folder / "slope.obj", mesh_size=WEDGE_MESH_SIZE),
                            density=1.0).centroid
    h = DN / cells_per_dn
    cells = [int(round(n / h)) for n in (LENGTH, WIDTH, TOP)]
    angle = math.atan(1.0 / COTANGENT)
    foot_z = DEPTH - FOOT_BELOW_SWL
    foot_x = TOE + COTANGENT * foot_z
    lift = 0.5 * DN + GAP
    centre = (foot_x - lift * math.sin(angle), 0.5 * WIDTH, foot_z + lift * math.cos(angle))
    # a turn of -angle about y puts the cube's x along the slope and its z along the normal
    quaternion = (math.cos(angle / 2), 0.0, -math.sin(angle / 2), 0.0)
    end = RECORD_FROM + RECORD_PERIODS * PERIOD
    text = f"""# A cube held on a 1:1.5 slope under regular waves (riprap.benchmarks.held_cube_flume).
format_version = 1

[simulation]
end_time = {end:.6g}
output_interval = {end:.6g}

[fluid]
lower = [0.0, 0.0, 0.0]
upper = [{LENGTH}, {WIDTH}, {TOP}]
cells = [{cells[0]}, {cells[1]}, {cells[2]}]
surface_tension = 0.0
max_time_step = {max_time_step:.6g}
cut_faces = "{cut_faces}"

[[water_regions]]
type = "level"
level = {DEPTH}

[waves]
type = "stream_function"
still_water_level = {DEPTH}
height = {HEIGHT}
period = {PERIOD}
absorbing_end = false

[[materials]]
name = "concrete"
density = 2400.0
friction_coefficient = 0.6
restitution = 0.3
contact_penalty = 1e8

[[shapes]]
name = "slope"
type = "mesh_file"
file = "slope.obj"
mesh_size = {WEDGE_MESH_SIZE}

[[shapes]]
name = "cube"
type = "cube"
side = {DN}

[[bodies]]
shape = "slope"
material = "concrete"
position = [{wedge[0]:.12g}, {wedge[1]:.12g}, {wedge[2]:.12g}]
fixed = true

[[bodies]]
shape = "cube"
material = "concrete"
position = [{centre[0]:.9g}, {centre[1]:.9g}, {centre[2]:.9g}]
orientation = [{quaternion[0]:.9g}, {quaternion[1]:.9g}, {quaternion[2]:.9g}, {quaternion[3]:.9g}]
fixed = true

[output]
directory = "out"
"""
    path = folder / "case.toml"
    path.write_text(text)
    return path

