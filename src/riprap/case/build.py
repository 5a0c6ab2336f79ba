"""Build a :class:`riprap.simulation.Simulation` from a validated :class:`riprap.case.load.Case`.

Everything here is available from Python too: the case file and the API use the same names.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.case.body_start import check_body_starts, check_coordinates, shape_radius
from riprap.case.run_record import RunDefinition
from riprap.case.specs import keywords_for
from riprap.deformable import ElasticMaterial
from riprap.deformable.joints import JointMaterial
from riprap.errors import CaseFileError, RiprapError
from riprap.geometry import shapes as builtin_shapes
from riprap.geometry.armour_units import armour_unit
from riprap.geometry.meshing import check_body_length
from riprap.geometry.tetmesh import TetMesh
from riprap.io.contact_history import ContactHistory, read_contact_history
from riprap.io.mesh_files import read_mesh
from riprap.schema import default_of, format_toml_value
from riprap.simulation import Simulation
from riprap.solid import walls as wall_builders
from riprap.solid.materials import FrictionPair, Material, pair_naming


def build_material(spec) -> Material:
    """The :class:`Material` of a ``[[materials]]`` entry."""
    return Material(**keywords_for(Material, spec))


def build_friction_pairs(case) -> tuple[FrictionPair, ...]:
    """The :class:`FrictionPair` of each ``[[friction]]`` entry of ``case`` (a pack's first)."""
    return tuple(FrictionPair(materials=spec.materials,
                              friction_coefficient=spec.friction_coefficient)
                 for spec in case.friction)


def build_shape(spec) -> TetMesh:
    """The tetrahedral mesh of a ``[[shapes]]`` entry."""
    p = dict(spec.parameters)
    mesh_size = spec.mesh_size if spec.mesh_size > 0 else None
    if spec.type == "mesh_file":
        mesh = read_mesh(p["file"], mesh_size=mesh_size)
        scale = float(p.get("scale", 1.0))
        # the (scaled) body must be a size riprap meshes, as a sphere's radius must: a scale of
        # 1e150 overflows its volume, a body a micrometre across needs tens of millions of
        # contact steps a second of simulated time
        extent = float(np.ptp(mesh.nodes, axis=0).max())
        with np.errstate(over="ignore", under="ignore"):
            check_body_length(np.float64(extent) * scale,
                              "scale x the mesh's extent" if scale != 1.0 else "the mesh's extent",
                              f"mesh_file '{p['file']}' (extent {extent:.4g} m"
                              + (f", scale {scale:g})" if scale != 1.0 else ")"))
        if scale != 1.0:
            mesh = TetMesh(nodes=mesh.nodes * scale, tets=mesh.tets, name=mesh.name)
        return mesh
    builders = {
        "sphere": lambda: builtin_shapes.sphere(radius=p["radius"], mesh_size=mesh_size),
        "box": lambda: builtin_shapes.box(lengths=tuple(p["lengths"]), mesh_size=mesh_size),
        "cube": lambda: builtin_shapes.cube(side=p["side"], mesh_size=mesh_size),
        "random_rock": lambda: builtin_shapes.random_rock(
            size=p["size"], elongation=p["elongation"], flatness=p["flatness"], seed=p["seed"],
            n_vertices=p["n_vertices"], mesh_size=mesh_size),
        "tetrapod": lambda: builtin_shapes.tetrapod(height=p["height"], mesh_size=mesh_size),
        "l_shape": lambda: builtin_shapes.l_shape(length=p["length"], width=p["width"],
                                                  thickness=p["thickness"], mesh_size=mesh_size),
        "armour_unit": lambda: armour_unit(p["unit_kind"], height=p["unit_height"],
                                           mesh_size=mesh_size).mesh,
    }
    return builders[spec.type]()


# With RIPRAP_SMOKE=1 every run stops after this much simulated time (s): the examples are run
# by the test suite this way, so they cannot rot.
SMOKE_END_TIME = 0.01


def smoke_mode() -> bool:
    return os.environ.get("RIPRAP_SMOKE", "") == "1"


def build_simulation(case, *, output_directory: str | Path | None = None,
                     progress: bool = True) -> Simulation:
    """Shapes, materials, bodies and walls of ``case`` in a ready-to-run Simulation."""
    settings = case.simulation
    end_time = min(settings.end_time, SMOKE_END_TIME) if smoke_mode() else settings.end_time
    sim = Simulation(
        end_time=end_time, time_step=settings.time_step,
        time_step_safety=settings.time_step_safety, gravity=settings.gravity,
        output_interval=settings.output_interval, checkpoint_interval=settings.checkpoint_interval,
        local_damping=settings.local_damping, rest_speed=settings.rest_speed,
        adaptive_time_step=settings.adaptive_time_step,
        output_directory=output_directory or case.output.directory,
        paraview=case.output.paraview, picture=case.output.picture, progress=progress,
        body_forces_interval=case.output.body_forces_interval)
    if case.source and Path(case.source).is_file():
        sim.case_file = str(Path(case.source).resolve())
    sim.run_definition = RunDefinition.of(case)
    for m in case.materials:
        sim.add_material(build_material(m))
    for pair in build_friction_pairs(case):
        sim.add_friction_pair(pair)
    radii = {}
    for spec in case.shapes:
        try:
            mesh = build_shape(spec)
        except RiprapError as error:
            # The shape builders name the key and value; the case file names the entry.
            raise type(error)(f"{case.source}: [[shapes]] '{spec.name}': {error}") from None
        sim.add_shape(spec.name, mesh)
        radii[spec.name] = shape_radius(mesh)
    check_body_starts(case, radii.__getitem__)
    place = _BodyPlacer(sim, case)
    for body in case.bodies:
        place(shape=body.shape, material=body.material, position=body.position,
              orientation=body.orientation, velocity=body.velocity,
              angular_velocity=body.angular_velocity, fixed=body.fixed)
    rng = np.random.default_rng(settings.seed)
    for grid in case.body_grids:
        add_body_grid(sim, grid, rng, place=place)
    place.check_selection()
    add_case_walls(sim, case)
    add_case_strip(sim, case)
    if settings.contact_history:
        history = read_contact_history(settings.contact_history, n_bodies=place.count,
                                       n_walls=len(sim.solver.walls))
        sim.set_contact_history(place.split_history(history))
    return sim


def add_case_walls(sim: Simulation, case) -> None:
    """The ``[[walls]]`` of ``case``."""
    for number, wall in enumerate(case.walls):
        where = f"{case.source} [[walls]] entry {number + 1}"
        for key in ("point", "min", "max"):
            if key in wall.parameters:
                check_coordinates(where, key, wall.parameters[key])
        if wall.type == "plane":
            sim.add_walls(wall_builders.plane(point=wall.parameters["point"],
                                              normal=wall.parameters["normal"],
                                              material=wall.material))
        else:
            lo, hi = wall.parameters["min"], wall.parameters["max"]
            sim.add_walls(wall_builders.box(min=lo, max=hi, material=wall.material,
                                            open_top=wall.parameters["open_top"]),
                          container_box=(tuple(lo), tuple(hi)))


def add_case_strip(sim: Simulation, case) -> None:
    """``[simulation] periodic_y_low`` .. ``periodic_y_high``: the bodies' periodic strip (a
    [fluid] with periodic y sides sets its own when the coupling starts)."""
    low, high = case.simulation.periodic_y_low, case.simulation.periodic_y_high
    if low == 0.0 and high == 0.0:
        return
    where = f"{case.source} [simulation]"
    if not high > low:
        raise CaseFileError(f"{where}: periodic_y_high = {high!r} m must exceed periodic_y_low = "
                            f"{low!r} m (both 0: no strip)")
    fluid = case.fluid
    if fluid is not None:
        if not (fluid.y_low == fluid.y_high == "periodic"):
            raise CaseFileError(f"{where}: periodic_y_low/high make the bodies a periodic strip, "
                                "but the [fluid] box has walls at its y sides; give it y_low = "
                                "y_high = \"periodic\"")
        if (low, high) != (float(fluid.lower[1]), float(fluid.upper[1])):
            raise CaseFileError(f"{where}: the bodies' strip y {low:g} .. {high:g} m is not the "
                                f"[fluid] box's y range {fluid.lower[1]:g} .. "
                                f"{fluid.upper[1]:g} m")
    try:
        sim.solver.set_periodic(1, low, high)
    except CaseFileError as error:
        raise CaseFileError(f"{where}: {error}") from None


class _BodyPlacer:
    """Adds the case's bodies in order, as rigid bodies or, where ``[deformable]`` selects them,
    as deformable ones (their ElasticMaterial from ``[deformable]`` and their material's
    density)."""

    def __init__(self, sim: Simulation, case):
        self.sim = sim
        self.case = case
        self.spec = case.deformable
        self.count = 0
        self.rigid_case_index = []
        self._materials = {}
        if self.spec is not None:
            sim.deformable_contact_penalty = self.spec.contact_penalty or None
            sim.deformable_mass_damping = self.spec.mass_damping

    def _elastic_material(self, name: str):
        if name not in self._materials:
            spec = self.spec
            pair = pair_naming(self.case.friction, name)
            if pair is not None:
                raise RiprapError(
                    f"{self.case.source}: [[friction]] materials = "
                    f"{format_toml_value(list(pair.materials))}: names '{name}', the material of "
                    "a deformable body ([deformable] bodies); a [[friction]] pair reaches the "
                    "rigid contacts only (a deformable body's contact takes the smaller of the two "
                    "coefficients): remove the entry or keep those bodies rigid")
            source = next(m for m in self.case.materials if m.name == name)
            self._materials[name] = ElasticMaterial(
                name=name, density=source.density, friction_coefficient=source.friction_coefficient,
                restitution=source.restitution,
                young_modulus=spec.young_modulus,
                poisson_ratio=spec.poisson_ratio, viscosity=spec.viscosity,
                constitutive_model=spec.constitutive_model,
                tensile_strength=spec.tensile_strength or None)
        return self._materials[name]

    def _joint_material(self):
        """The joints of ``[deformable] fracture``, every strength and energy checked > 0."""
        spec = self.spec
        where = f"{self.case.source}: [deformable] fracture = true"
        if spec.element_type != "tet4":
            raise RiprapError(f"{where} needs element_type = \"tet4\" (joints hold the faces of "
                              f"4-node tets), not {spec.element_type!r}")
        hints = {"tensile_strength": "Pa; concrete about 3e6",
                 "cohesion": "Pa; concrete about twice the tensile strength",
                 "fracture_energy_mode_i": "J/m^2; concrete about 100",
                 "fracture_energy_mode_ii": "J/m^2; concrete about 1000"}
        for key, hint in hints.items():
            if not getattr(spec, key) > 0:
                raise RiprapError(f"{where} needs {key} > 0 ({hint}); it is {getattr(spec, key)!r}")
        penalty = spec.joint_penalty or 10.0 * spec.young_modulus
        if not math.isfinite(penalty):
            raise RiprapError(f"{self.case.source}: [deformable] young_modulus = "
                              f"{spec.young_modulus:g} Pa makes the default joint_penalty (10 "
                              "young_modulus per metre) infinite; give young_modulus in Pa "
                              "(concrete about 3e10)")
        return JointMaterial(
            tensile_strength=spec.tensile_strength, cohesion=spec.cohesion,
            friction_angle=spec.friction_angle,
            fracture_energy_mode_i=spec.fracture_energy_mode_i,
            fracture_energy_mode_ii=spec.fracture_energy_mode_ii,
            joint_penalty=penalty)

    def __call__(self, *, shape, material, position,
                 orientation=default_of("bodies", "orientation"),
                 velocity=default_of("bodies", "velocity"),
                 angular_velocity=default_of("bodies", "angular_velocity"),
                 fixed=default_of("bodies", "fixed")) -> None:
        index = self.count
        self.count += 1
        if self.spec is not None and self.spec.selects(index):
            if fixed:
                raise RiprapError(f"{self.case.source}: [deformable] bodies selects body {index}, "
                                  "which is fixed; a fixed body cannot deform")
            cracking = None
            if self.spec.cracks(index):
                cracking = (self._joint_material(), (self.spec.fracture_region_lower,
                                                     self.spec.fracture_region_upper))
            self.sim.add_deformable_body(
                shape=shape, material=self._elastic_material(material), position=position,
                orientation=orientation, velocity=velocity, angular_velocity=angular_velocity,
                element_type=self.spec.element_type, name=f"body_{index}",
                joints=cracking)
            self.sim.deformable_case_index.append(index)
        else:
            self.rigid_case_index.append(index)
            self.sim.add_body(shape=shape, material=material, position=position,
                              orientation=orientation, velocity=velocity,
                              angular_velocity=angular_velocity, fixed=fixed)

    def split_history(self, history):
        """The contact history of the rigid bodies, renumbered as the rigid solver numbers them;
        the resting overlaps of the deformable bodies' contacts go to
        ``sim.deformable_accepted_depths`` (keyed by case body numbers, walls -1 - w)."""
        if not self.sim.deformable_bodies:
            return history
        rigid = np.full(self.count, -1, dtype=np.int64)
        rigid[self.rigid_case_index] = np.arange(len(self.rigid_case_index))

        def solver_index(i):
            return i if i < 0 else rigid[i]

        keep = []
        for row, (i, j) in enumerate(zip(history.body_i, history.body_j)):
            if solver_index(i) >= 0 and (j < 0 or solver_index(j) >= 0):
                keep.append(row)
            else:
                self.sim.deformable_accepted_depths[(int(i), int(j))] = float(history.overlap_depths[row])
        keep = np.asarray(keep, dtype=np.int64)
        return ContactHistory([solver_index(i) for i in history.body_i[keep]],
                              [solver_index(j) for j in history.body_j[keep]],
                              history.springs[keep], history.overlap_depths[keep])

    def check_selection(self) -> None:
        spec = self.spec
        if spec is not None and spec.bodies != "all":
            missing = [i for i in spec.bodies if i >= self.count]
            if missing:
                raise RiprapError(f"{self.case.source}: [deformable] bodies lists {missing}, but the "
                                  f"case makes {self.count} bodies (numbered 0 to {self.count - 1})")
        if spec is not None and spec.fracture and spec.fracture_bodies != "all":
            missing = [i for i in spec.fracture_bodies if i >= self.count]
            if missing:
                raise RiprapError(f"{self.case.source}: [deformable] fracture_bodies lists {missing}, "
                                  f"but the case makes {self.count} bodies (numbered 0 to "
                                  f"{self.count - 1})")
            rigid = [i for i in spec.fracture_bodies if not spec.selects(i)]
            if rigid:
                raise RiprapError(f"{self.case.source}: [deformable] fracture_bodies lists {rigid}, "
                                  "which stay rigid (not in [deformable] bodies): joints crack "
                                  "deformable bodies only; add them to bodies")


def add_body_grid(sim: Simulation, grid, rng: np.random.Generator, place=None) -> None:
    """Bodies on a rectangular grid, with random or identity orientations and optional jitter."""
    place = place or sim.add_body
    nx, ny, nz = grid.counts
    k = 0
    for iz in range(nz):
        for iy in range(ny):
            for ix in range(nx):
                if grid.shape_choice == "random":
                    shape = grid.shapes[int(rng.integers(len(grid.shapes)))]
                else:
                    shape = grid.shapes[k % len(grid.shapes)]
                position = np.asarray(grid.origin) + np.asarray(grid.spacing) * (ix, iy, iz)
                if grid.jitter > 0:
                    position = position + rng.uniform(-grid.jitter, grid.jitter, 3)
                if grid.orientation == "random":
                    x, y, z, w = Rotation.random(random_state=rng).as_quat()
                    orientation = (w, x, y, z)
                else:
                    orientation = (1.0, 0.0, 0.0, 0.0)
                place(shape=shape, material=grid.material, position=position,
                      orientation=orientation, velocity=grid.velocity)
                k += 1
