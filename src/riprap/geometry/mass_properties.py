"""Volume, mass, centroid and inertia tensor of a tetrahedral mesh of uniform density.

The integrals are exact for the meshed body: each tetrahedron contributes its volume, first
moment and second moment (covariance) in closed form, and the sums are vectorised with numpy.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, MeshError
from riprap.geometry.tetmesh import TetMesh


@dataclass(frozen=True, eq=False)
class MassProperties:
    """Mass properties of a rigid body of uniform density.

    Attributes
    ----------
    volume : float
        Volume in m^3.
    mass : float
        Mass in kg.
    centroid : numpy.ndarray, shape (3,)
        Centre of mass in metres, in the mesh frame.
    inertia_tensor : numpy.ndarray, shape (3, 3)
        Inertia tensor about the centroid, in kg m^2, axes of the mesh frame.
    principal_moments : numpy.ndarray, shape (3,)
        Eigenvalues of ``inertia_tensor`` in ascending order, kg m^2.
    principal_axes : numpy.ndarray, shape (3, 3)
        Columns are the unit principal axes matching ``principal_moments``; the matrix is a proper
        rotation (determinant +1), so ``principal_axes.T @ inertia_tensor @ principal_axes`` is
        ``diag(principal_moments)``.
    """

    volume: float
    mass: float
    centroid: np.ndarray
    inertia_tensor: np.ndarray
    principal_moments: np.ndarray
    principal_axes: np.ndarray


def mass_properties(mesh: TetMesh, *, density: float = 1.0) -> MassProperties:
    """Exact mass properties of a tetrahedral mesh of uniform density.

    Parameters
    ----------
    mesh : TetMesh
        Positively oriented tetrahedral mesh, coordinates in metres.
    density : float
        Density in kg/m^3 (default 1, so that ``mass`` equals ``volume``).

    Returns
    -------
    MassProperties

    Raises
    ------
    MeshError
        If a tetrahedron has non-positive volume (the integrals would silently subtract it).
    CaseFileError
        If ``density`` is not positive and finite.

    Notes
    -----
    For a tetrahedron with vertices :math:`x_0..x_3` and volume :math:`V`, the second moment is
    :math:`\\int x x^T dV = \\frac{V}{20}\\left(\\sum_i x_i x_i^T + s s^T\\right)` with
    :math:`s = \\sum_i x_i`, which follows from mapping the canonical tetrahedron (whose covariance
    has 1/60 on the diagonal and 1/120 off it) onto the element. Coordinates are taken relative
    to the mean node position first, so that bodies far from the origin keep full precision. The
    inertia tensor about the centroid is :math:`\\rho (\\mathrm{tr}(C) I - C)` with :math:`C`
    the second moment about the centroid.

    References
    ----------
    Tonon, F. (2004). Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of
    its vertex coordinates. Journal of Mathematics and Statistics 1(1), 8-11.

    Examples
    --------
    >>> import numpy as np
    >>> from riprap.geometry.tetmesh import TetMesh
    >>> mesh = TetMesh(nodes=np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
    ...                tets=np.array([[0, 1, 2, 3]]))
    >>> properties = mass_properties(mesh, density=2650.0)
    >>> round(properties.mass, 6), properties.centroid.tolist()
    (441.666667, [0.25, 0.25, 0.25])
    """
    density = float(density)
    if not (np.isfinite(density) and density > 0.0):
        raise CaseFileError(
            f"mass_properties of mesh '{mesh.name}': density must be a positive number in kg/m^3, "
            f"got {density}"
        )
    if mesh.n_tets == 0:
        raise MeshError(f"mesh '{mesh.name}' has no tetrahedra; cannot compute mass properties")
    reference = mesh.nodes[np.unique(mesh.tets)].mean(axis=0)
    corners = mesh.nodes[mesh.tets] - reference  # (n_tets, 4, 3)
    volumes = np.linalg.det(corners[:, 1:, :] - corners[:, :1, :]) / 6.0
    if not np.all(volumes > 0.0):
        worst = np.argsort(volumes)[:5]
        raise MeshError(
            f"mesh '{mesh.name}' has {(volumes <= 0.0).sum()} tetrahedra with non-positive volume "
            f"(e.g. tets {worst.tolist()}); run mesh.check() for details and fix the orientation"
        )
    volume = float(volumes.sum())
    sums = corners.sum(axis=1)  # (n_tets, 3)
    centroid_relative = (volumes[:, None] * sums).sum(axis=0) / (4.0 * volume)
    vertex_products = np.einsum("tki,tkj->tij", corners, corners)
    sum_products = np.einsum("ti,tj->tij", sums, sums)
    second_moment = np.einsum("t,tij->ij", volumes / 20.0, vertex_products + sum_products)
    second_moment -= volume * np.outer(centroid_relative, centroid_relative)
    inertia = density * (np.trace(second_moment) * np.eye(3) - second_moment)
    inertia = 0.5 * (inertia + inertia.T)
    moments, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] = -axes[:, 2]
    return MassProperties(
        volume=volume,
        mass=density * volume,
        centroid=centroid_relative + reference,
        inertia_tensor=inertia,
        principal_moments=moments,
        principal_axes=axes,
    )
