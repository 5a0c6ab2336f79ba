"""What the analysis reads: one state of an armour layer, as flat arrays (no files, no solver).

A :class:`LayerState` is a snapshot of every body (pose, shape, material, fixed or free), the plane
walls, the contacts between them with their forces, and the :class:`LayerDescription` that says
which bodies are armour units, where they were meant to go and how the slope lies. It is made
from a pack folder or a frame of a run by :mod:`riprap.workflows.layer_input`, or directly from a
running :class:`riprap.Simulation` by :func:`state_from_simulation`.

Frames. ``rotations[b]`` turns the mesh of the body's shape, as stored in ``meshes``, into the
world; a node ``p`` of that mesh is at ``positions[b] + rotations[b] @ (p - mesh_centroids[k])``.
The unit axes of the description (``unit_axes``) are unit vectors in the frame of the unit's mesh
as stored, so that a unit's axis in the world is ``rotations[b] @ axis``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from riprap.errors import CaseFileError
from riprap.geometry.mass_properties import mass_properties
from riprap.placement.slope import Slope
from riprap.solid.contact_statistics import pair_friction
from riprap.solid.materials import friction_table

__all__ = ["LayerDescription", "LayerState", "state_from_simulation", "ROCK_ARMOUR_KIND"]

#: ``unit_kind`` of a layer of graded armour stone (``riprap place`` of ``[armour_stone]``).
ROCK_ARMOUR_KIND = "armour_stone"


@dataclass(frozen=True, eq=False)
class LayerDescription:
    """The armour layer of a pack: which bodies are units, their design, the slope.

    Attributes
    ----------
    unit_kind : str
        Armour unit kind (``riprap.geometry.armour_units.UNIT_KINDS``).
    unit_shape : str or tuple of str
        Name of the units' shape in the pack; for rock armour (``unit_kind`` ``"armour_stone"``)
        the names of the stones' shapes, one per stone of the grading's library.
    nominal_diameter : float
        D_n = V^(1/3) of a unit (m); of rock armour, the placed stones' D_n50.
    unit_volume : float
        Volume of one unit (m^3); of rock armour, the placed stones' mean volume.
    unit_height : float
        Characteristic height H of a unit (m); of rock armour, D_n50.
    unit_axes : dict of str to (3,) array
        Named unit vectors in the frame of the unit's mesh as stored; the first is the one whose
        fabric and stereonet the analysis gives (``"nose"`` of a concrete unit, ``"long"`` of a
        stone: its axis of least inertia).
    slope : Slope
        The face the layer rests on.
    underlayer_top : float
        Level of the underlayer's top above the face (m), from which the layer thickness counts.
    unit_bodies : (n_units,) int
        Body index of each unit; unit ``k`` of every table is body ``unit_bodies[k]``.
    rows : (n_units,) int
        Placement row of each unit.
    design_positions : (n_units, 3) float
        Where each unit was meant to go (the grid point of its centroid), world m.
    design : dict
        Design figures: ``packing_density_coefficient``, ``layer_thickness_m``, ``porosity``.
    """

    unit_kind: str
    unit_shape: str
    nominal_diameter: float
    unit_volume: float
    unit_height: float
    unit_axes: dict
    slope: Slope
    underlayer_top: float
    unit_bodies: np.ndarray
    rows: np.ndarray
    design_positions: np.ndarray
    design: dict = field(default_factory=dict)

    @property
    def n_units(self) -> int:
        return len(self.unit_bodies)

    @property
    def unit_shape_names(self) -> tuple:
        """The shape names the units may have (one for concrete units)."""
        return (self.unit_shape,) if isinstance(self.unit_shape, str) else tuple(self.unit_shape)

    @property
    def primary_axis(self) -> str:
        """The axis whose fabric the analysis reports (the first of ``unit_axes``)."""
        return next(iter(self.unit_axes))

    @property
    def is_rock(self) -> bool:
        """Rock armour (graded stones), judged by S and the rock formulas."""
        return self.unit_kind == ROCK_ARMOUR_KIND

    @classmethod
    def from_fields(cls, fields: dict) -> "LayerDescription":
        """The description read from a ``layer.json`` (:func:`riprap.io.layer_file.read_layer_file`
        gives its fields as plain data); a slope the :class:`Slope` refuses is named with the
        file and line of its field."""
        fields = dict(fields)
        where = fields.pop("slope_source", "layer.json")
        try:
            slope = Slope(**fields.pop("slope"))
        except CaseFileError as error:
            raise CaseFileError(f"{where}: 'slope': {error}") from None
        return cls(slope=slope, **fields)

    @classmethod
    def for_unit(cls, unit, unit_shape, *, slope, underlayer_top, unit_bodies, rows,
                 design_positions) -> "LayerDescription":
        """The description of a layer of ``unit`` (an ``ArmourUnit``) whose bodies use
        ``unit_shape`` (its ``RigidShape``, whose principal-frame mesh the pack stores)."""
        # The unit's axes are given in the frame it was built in; the pack stores the mesh in
        # its principal frame, nodes p = A^T (b - c): an axis v becomes A^T v.
        axes = {name: unit_shape.frame_rotation.T @ np.asarray(axis, dtype=float)
                for name, axis in unit.axes.items()}
        design = unit.design
        return cls(
            unit_kind=unit.kind, unit_shape=unit_shape.name, nominal_diameter=unit.nominal_diameter,
            unit_volume=unit.volume, unit_height=unit.height, unit_axes=axes, slope=slope,
            underlayer_top=float(underlayer_top), unit_bodies=np.asarray(unit_bodies, dtype=np.int64),
            rows=np.asarray(rows, dtype=np.int64),
            design_positions=np.asarray(design_positions, dtype=float).reshape(-1, 3),
            design={"packing_density_coefficient": design.packing_density_coefficient,
                    "layer_thickness_m": design.layers * design.layer_thickness_coefficient
                    * unit.nominal_diameter,
                    "porosity": design.porosity})

    @classmethod
    def for_stones(cls, *, shape_names, nominal_diameter, mean_volume, design, slope,
                   underlayer_top, unit_bodies, rows, design_positions, filter_dn50,
                   grading_ratio) -> "LayerDescription":
        """The description of a layer of graded armour stone: ``shape_names`` the stones' shapes
        in the pack (each stored in its principal frame, axes by increasing moment of inertia: x
        the long axis, z the short one); ``nominal_diameter`` the placed stones' D_n50,
        ``mean_volume`` their mean volume; ``design`` a
        :class:`riprap.placement.armour_stones.StoneLayerDesign`; ``filter_dn50`` the
        underlayer's D_n50 and ``grading_ratio`` the placed stones' D_n85 / D_n15 (for the rock
        formulas)."""
        return cls(
            unit_kind=ROCK_ARMOUR_KIND, unit_shape=tuple(shape_names),
            nominal_diameter=float(nominal_diameter), unit_volume=float(mean_volume),
            unit_height=float(nominal_diameter),
            unit_axes={"long": np.array([1.0, 0.0, 0.0]), "short": np.array([0.0, 0.0, 1.0])},
            slope=slope, underlayer_top=float(underlayer_top),
            unit_bodies=np.asarray(unit_bodies, dtype=np.int64),
            rows=np.asarray(rows, dtype=np.int64),
            design_positions=np.asarray(design_positions, dtype=float).reshape(-1, 3),
            # the packing density coefficient of n layers: N_a D_n50^2 = n k_t (1 - n_v)
            design={"packing_density_coefficient": design.stones_per_area * design.dn50 ** 2,
                    "layer_thickness_m": design.layer_thickness, "porosity": design.porosity,
                    "layers": float(design.layers), "dn50_m": design.dn50,
                    "filter_dn50_m": float(filter_dn50),
                    "placed_dn85_over_dn15": float(grading_ratio)})


@dataclass(frozen=True, eq=False)
class LayerState:
    """Bodies, walls and contacts of one state of a layer.

    Attributes
    ----------
    positions : (n, 3) float
        Centroid of each body (m).
    rotations : (n, 3, 3) float
        Rotation of each body's mesh (as stored) into the world.
    shape_of_body : (n,) int
        Index into ``meshes`` / ``shape_names``.
    shape_names : list of str
    meshes : list of TetMesh
        Each shape's tetrahedral mesh as stored (pack ``shapes/*.vtu``).
    mesh_centroids : (n_shapes, 3) float
        Centroid of each mesh (the point that ``positions`` places).
    material_of_body : (n,) int
        Index into ``materials``.
    materials : list of riprap.solid.materials.Material
    fixed : (n,) bool
    wall_points, wall_normals : (n_walls, 3) float
        Plane walls (unit outward normals).
    wall_materials : (n_walls,) int
        Index into ``materials``.
    contacts : riprap.solid.solver.ContactRecords
        One row per touching pair; forces on ``body_i``; ``body_j = -1 - w`` for wall ``w``.
    gravity : (3,) float
        m/s^2.
    time : float
        Simulated time of the state (s).
    layer : LayerDescription
    source : str
        Where the state was read from (named in the report and in errors).
    reference_positions, reference_rotations : (n, 3) and (n, 3, 3) float, or None
        The same bodies' poses in the state the displacements are measured from (frame 0 of a
        run); None: no reference (a pack on its own), the displacement columns are NaN.
    reference_time : float
        Simulated time of the reference state (s).
    reference_note : str
        What the reference is, or why there is none.
    contacts_recorded : bool
        False when the source recorded no contacts (a coupled run writes no ``contacts.pvd``):
        ``contacts`` is then empty because nothing was recorded, not because nothing touches.
    rotation_history : (frames, n) float or None
        Each body's rotation (degrees) from its reference pose in every frame up to this state's
        (a run's frames 0..frame), for counting rocking; None without frames.
    friction_pairs : tuple of riprap.solid.materials.FrictionPair
        Friction coefficients of named pairs of materials (the case's ``[[friction]]``); other
        pairs take the smaller of the two materials'.
    """

    positions: np.ndarray
    rotations: np.ndarray
    shape_of_body: np.ndarray
    shape_names: list
    meshes: list
    mesh_centroids: np.ndarray
    material_of_body: np.ndarray
    materials: list
    fixed: np.ndarray
    wall_points: np.ndarray
    wall_normals: np.ndarray
    wall_materials: np.ndarray
    contacts: object
    gravity: np.ndarray
    time: float
    layer: LayerDescription
    source: str = ""
    reference_positions: np.ndarray | None = None
    reference_rotations: np.ndarray | None = None
    reference_time: float = float("nan")
    reference_note: str = ""
    contacts_recorded: bool = True
    rotation_history: np.ndarray | None = None
    friction_pairs: tuple = ()
    _faces: dict = field(default_factory=dict, repr=False)

    @property
    def n_bodies(self) -> int:
        return len(self.positions)

    def boundary_faces(self, body: int) -> np.ndarray:
        """Boundary triangles (node indices of the stored mesh) of ``body``'s shape."""
        k = int(self.shape_of_body[body])
        if k not in self._faces:         # one per shape: thousands of rocks share a few shapes
            self._faces[k] = self.meshes[k].boundary_faces()
        return self._faces[k]

    def world_nodes(self, body: int) -> np.ndarray:
        """Nodes of ``body``'s mesh in the world (m)."""
        k = int(self.shape_of_body[body])
        local = self.meshes[k].nodes - self.mesh_centroids[k]
        return local @ self.rotations[body].T + self.positions[body]

    def masses(self) -> np.ndarray:
        """Mass of each body (kg)."""
        volumes = np.array([mass_properties(mesh, density=1.0).volume for mesh in self.meshes])
        density = np.array([m.density for m in self.materials])
        return volumes[self.shape_of_body] * density[self.material_of_body]

    def contact_friction(self) -> np.ndarray:
        """Friction coefficient of each contact row, as the run gave it (the pair's
        ``[[friction]]`` entry, else the smaller of the two materials')."""
        return pair_friction(self.contacts, friction_table(self.materials, self.friction_pairs),
                             self.material_of_body, self.wall_materials)


def state_from_simulation(sim, layer: LayerDescription, *, source: str = "simulation") -> LayerState:
    """The current state of a :class:`riprap.Simulation` (its solver's bodies, walls and contacts)."""
    solver = sim.solver
    meshes = [shape.mesh for shape in solver.shapes]
    names = [None] * len(meshes)
    for name, index in sim.shape_names.items():
        names[index] = name
    walls = solver.walls
    material_index = {m.name: k for k, m in enumerate(solver.materials)}
    return LayerState(
        positions=solver.positions.copy(), rotations=solver.rotation_matrices().copy(),
        shape_of_body=np.asarray(solver.shape_index, dtype=np.int64).copy(), shape_names=names,
        meshes=meshes,
        mesh_centroids=np.array([mass_properties(mesh, density=1.0).centroid for mesh in meshes]),
        material_of_body=np.asarray(solver.material_index_of_body, dtype=np.int64).copy(),
        materials=list(solver.materials), fixed=np.asarray(solver.fixed, dtype=bool).copy(),
        wall_points=np.array([w.point for w in walls], dtype=float).reshape(-1, 3),
        wall_normals=np.array([w.normal for w in walls], dtype=float).reshape(-1, 3),
        wall_materials=np.array([material_index[w.material] for w in walls], dtype=np.int64),
        contacts=solver.contacts, gravity=np.asarray(solver.gravity, dtype=float).copy(),
        time=float(solver.time), layer=layer, source=source,
        friction_pairs=tuple(solver.friction_pairs))
