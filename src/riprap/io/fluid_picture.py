"""Quick-look PNG of the free surface: the water in a vertical x-z section (the middle of the flume
in y for a 3D grid), shaded by the water fraction, with the 0.5 contour drawn and the velocity as
arrows on a coarse lattice."""
from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["free_surface_png"]

_ARROWS_ACROSS = 24


def free_surface_png(path, *, grid, fraction, velocity, solid, time: float, bodies=None) -> Path:
    """Write the section picture; ``velocity`` (nx, ny, nz, 3) at cell centres (m/s); ``bodies``
    (nx, ny, nz), optional: the solid fraction of the moving bodies, drawn cut by the section."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    j = grid.cells[1] // 2
    section = fraction[:, j, :].T               # (nz, nx): rows are heights
    x_faces, z_faces = grid.faces(0), grid.faces(2)
    width = grid.upper[0] - grid.lower[0]
    height = grid.upper[2] - grid.lower[2]
    figure, axes = plt.subplots(figsize=(8.0, max(2.5, 8.0 * height / width + 0.8)))
    image = axes.pcolormesh(x_faces, z_faces, section, cmap="Blues", vmin=0.0, vmax=1.0,
                            shading="flat")
    if solid.any():
        axes.pcolormesh(x_faces, z_faces, np.ma.masked_where(~solid[:, j, :].T, solid[:, j, :].T),
                        cmap="Greys", vmin=0, vmax=1.5, shading="flat")
    if bodies is not None and bodies[:, j, :].max(initial=0.0) > 0.0:
        cut = bodies[:, j, :].T
        axes.pcolormesh(x_faces, z_faces, np.ma.masked_where(cut < 0.02, cut), cmap="copper_r",
                        vmin=0.0, vmax=1.6, shading="flat")
        axes.contour(grid.centres(0), grid.centres(2), cut, levels=[0.5], colors="saddlebrown",
                     linewidths=1.0)
    xc, zc = grid.centres(0), grid.centres(2)
    if section.max() > 0.5 > section.min():
        axes.contour(xc, zc, section, levels=[0.5], colors="navy", linewidths=1.0)
    stride = max(1, grid.cells[0] // _ARROWS_ACROSS)
    ux = velocity[::stride, j, ::stride, 0].T
    uz = velocity[::stride, j, ::stride, 2].T
    if np.abs(ux).max(initial=0.0) + np.abs(uz).max(initial=0.0) > 0:
        axes.quiver(xc[::stride], zc[::stride], ux, uz, color="crimson", width=0.002, alpha=0.7)
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("z (m)")
    where = "" if grid.two_dimensional else f" at y = {grid.centres(1)[j]:.3g} m"
    bodies_note = ", bodies cut by the section in brown" if bodies is not None else ""
    axes.set_title(f"water fraction{where}{bodies_note}, t = {time:.4f} s", fontsize=10)
    figure.colorbar(image, ax=axes, shrink=0.8, label="water fraction")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(figure)
    return path
