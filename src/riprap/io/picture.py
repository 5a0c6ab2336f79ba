"""Quick-look PNG pictures of bodies, drawn with matplotlib (no ParaView needed).

Faces are shaded with a Lambert (diffuse) law from a key light above and to the left of the
viewer and a weak fill light, so that the 3D shape of each body reads on paper. Each body gets a
distinct colour from a qualitative colour map, or a colour from a sequential map for one value
per body (e.g. maximum contact force), with a colour bar. Bodies that are context rather than
subject (the fixed rocks of an underlayer) can be drawn in a muted grey, and flat surfaces (a
slope face) as translucent planes.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.checkpoint import _atomic_target

__all__ = ["render_bodies_png", "bodies_to_draw"]

# Lighting: a key light above and to the left of the viewer, a weaker fill light from the
# lower right so that faces turned away from the key light still show their shape, and an
# ambient share so that no face goes black. The weights sum to a little over 1: colours keep
# their brightness, and only faces lit head-on by both lights (rare) clip to the full colour.
_AMBIENT = 0.42
_KEY_LIGHT = (0.55, 20.0, -80.0)  # (weight, elevation and azimuth offsets from the view, deg)
_FILL_LIGHT = (0.15, -20.0, 70.0)
# Resolution of the saved picture; size_px is divided by this to get the figure size in inches.
_DOTS_PER_INCH = 150
# Qualitative map for body colours, and the stride through it so that bodies with consecutive
# indices (often neighbours) get clearly different hues rather than tab20's light/dark pairs;
# the stride is prime to the 18 non-grey colours, so all of them are used.
_BODY_COLOUR_MAP = "tab20"
_BODY_COLOUR_STRIDE = 7
_VALUE_COLOUR_MAP = "viridis"
# Context bodies (e.g. fixed underlayer rocks): a mid grey, shaded like the rest, darker than the
# panes (0.96) and lighter than the text, and outside the body palette (its greys are removed).
_MUTED_GREY = (0.62, 0.62, 0.60)
# Planes (e.g. the slope face): a pale sand colour, see-through, so that bodies that the painter's
# algorithm draws before a plane tile still show through it. Planes are cut into about this many
# tiles along their longer side so that the tiles sort in depth among the bodies.
_PLANE_RGBA = (0.80, 0.72, 0.55, 0.35)
_PLANE_TILES = 32
# Tick intervals on the longest side of the box: one per this many pixels of picture width,
# within the bounds, so that tick labels do not overlap in small pictures.
_PIXELS_PER_TICK = 200
_TICK_COUNT_BOUNDS = (3, 7)


def _unit_vector(elevation_deg: float, azimuth_deg: float) -> np.ndarray:
    """Direction towards a point at the given elevation and azimuth (matplotlib's convention)."""
    elevation, azimuth = np.radians(elevation_deg), np.radians(azimuth_deg)
    horizontal = np.cos(elevation)
    return np.array([horizontal * np.cos(azimuth), horizontal * np.sin(azimuth), np.sin(elevation)])


def _lambert_intensity(triangles: np.ndarray, view: tuple[float, float]) -> np.ndarray:
    """Lambert (diffuse) intensity in [_AMBIENT, 1] of each triangle, shape (n_triangles,).

    Normals are flipped towards the viewer, so shading is right for the faces that can be seen
    whatever the winding order of the mesh. Data coordinates serve as display coordinates
    because the axes box is drawn with equal aspect.
    """
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    normals /= np.where(lengths > 0.0, lengths, 1.0)[:, None]
    towards_viewer = _unit_vector(*view)
    normals *= np.where(normals @ towards_viewer < 0.0, -1.0, 1.0)[:, None]
    intensity = np.full(len(triangles), _AMBIENT)
    for weight, elevation_offset, azimuth_offset in (_KEY_LIGHT, _FILL_LIGHT):
        towards_light = _unit_vector(view[0] + elevation_offset, view[1] + azimuth_offset)
        intensity += weight * np.clip(normals @ towards_light, 0.0, 1.0)
    return np.minimum(intensity, 1.0)


def _box_edges(lower: np.ndarray, upper: np.ndarray) -> list[np.ndarray]:
    """The 12 edges of an axis-aligned box, each as a (2, 3) array of end points."""
    corners = np.array(
        [[(upper if (k >> axis) & 1 else lower)[axis] for axis in range(3)] for k in range(8)]
    )
    edges = []
    for first in range(8):
        for axis in range(3):
            if not (first >> axis) & 1:
                edges.append(corners[[first, first | (1 << axis)]])
    return edges


def render_bodies_png(
    path: str | os.PathLike,
    *,
    triangles_world: Sequence[np.ndarray] | np.ndarray,
    body_ids: np.ndarray,
    values: np.ndarray | None = None,
    value_label: str = "",
    value_range: tuple[float, float] | None = None,
    colour_map: str = _VALUE_COLOUR_MAP,
    grey_bodies: Sequence[int] | np.ndarray | None = None,
    planes: Sequence[np.ndarray] | None = None,
    title: str = "",
    walls_box: tuple[Sequence[float], Sequence[float]] | None = None,
    view: tuple[float, float] = (25, -60),
    size_px: tuple[int, int] = (1400, 1000),
) -> Path:
    """Draw body surfaces as a shaded 3D picture and save it as PNG, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        PNG file to write; its folder is created if missing.
    triangles_world : numpy.ndarray, shape (n_triangles, 3, 3), or list of such arrays
        Boundary triangles of all bodies in world coordinates, metres: ``[triangle, corner,
        axis]``. A list is joined in order.
    body_ids : numpy.ndarray of int, shape (n_triangles,)
        Index of the body that each triangle belongs to (0-based).
    values : numpy.ndarray, shape (n_bodies,), optional
        One value per body, indexed by body index, used to colour the bodies (with a colour bar)
        instead of one distinct colour per body. ``n_bodies`` must exceed ``body_ids.max()``.
    value_label : str
        Colour-bar label for ``values``, with its unit, e.g. ``"maximum contact force (N)"``.
    value_range : (float, float), optional
        Values at the two ends of the colour scale; default the smallest and largest finite value
        of the bodies drawn. Values outside are drawn in the end colours, and the colour bar gets
        a pointed end on that side. Give the same range (and ``colour_map``) as a 2D figure of
        the same quantity so that equal colours mean equal values.
    colour_map : str
        Matplotlib colour map for ``values``.
    grey_bodies : array_like of int, optional
        Body indices drawn in a muted grey (context, e.g. fixed underlayer rocks): left out of the
        distinct colours and of the colour scale.
    planes : list of numpy.ndarray, shape (4, 3), optional
        Planar quadrilaterals, corners in order around the edge (m), drawn as translucent
        surfaces among the bodies, e.g. the slope face the bodies rest on. They count towards the
        extent of the axes.
    title : str
        Title written above the picture.
    walls_box : (array_like of 3, array_like of 3), optional
        Lower and upper corners of the container, metres, drawn as a wireframe.
    view : (float, float)
        Camera elevation and azimuth, degrees, as in matplotlib's ``Axes3D.view_init``.
    size_px : (int, int)
        Width and height of the picture, pixels.

    Returns
    -------
    pathlib.Path
        The PNG written.

    Raises
    ------
    CaseFileError
        If the arrays have the wrong shapes or there is nothing to draw.

    Notes
    -----
    Hidden surfaces are resolved by matplotlib's painter's algorithm (faces sorted by mean depth),
    which is right for separate convex-ish bodies and can misorder long interpenetrating faces;
    planes are therefore cut into tiles (``_PLANE_TILES`` along the longer side) and drawn
    translucent. About 100 000 triangles take some seconds.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    path = Path(path)
    where = f"picture {path}"
    if isinstance(triangles_world, np.ndarray):
        triangles = np.asarray(triangles_world, dtype=np.float64)
    else:
        parts = [np.asarray(part, dtype=np.float64).reshape(-1, 3, 3) for part in triangles_world]
        triangles = np.concatenate(parts) if parts else np.zeros((0, 3, 3))
    if triangles.ndim != 3 or triangles.shape[1:] != (3, 3) or len(triangles) == 0:
        raise CaseFileError(
            f"{where}: triangles_world has shape {triangles.shape}, expected a non-empty "
            "(n_triangles, 3, 3) array of corner coordinates."
        )
    body_ids = np.asarray(body_ids).reshape(-1)
    if body_ids.shape != (len(triangles),) or body_ids.dtype.kind not in "iu" or body_ids.min() < 0:
        raise CaseFileError(
            f"{where}: body_ids has shape {body_ids.shape} and dtype {body_ids.dtype}, expected "
            f"non-negative integers of shape ({len(triangles)},), one per triangle."
        )

    grey = np.zeros(len(triangles), dtype=bool)
    if grey_bodies is not None:
        grey = np.isin(body_ids, np.asarray(grey_bodies, dtype=np.int64).reshape(-1))
    if values is not None:
        values = np.asarray(values, dtype=np.float64).reshape(-1)
        if len(values) <= body_ids.max():
            raise CaseFileError(
                f"{where}: values has {len(values)} entries but body index {body_ids.max()} is "
                "used; give one value per body, indexed by body index."
            )
        shown = values[np.unique(body_ids[~grey])]
        finite = shown[np.isfinite(shown)]
        if value_range is not None:
            low, high = (float(v) for v in value_range)
        else:
            low, high = (finite.min(), finite.max()) if len(finite) else (0.0, 1.0)
        if high <= low:
            high = low + 1.0
        beyond_low, beyond_high = bool((shown < low).any()), bool((shown > high).any())
        colour_bar_extend = {(False, False): "neither", (True, False): "min",
                             (False, True): "max", (True, True): "both"}[beyond_low, beyond_high]
        norm = Normalize(vmin=low, vmax=high, clip=True)
        value_map = colormaps[colour_map]
        # inf is clipped to the top colour like any value above the range; nan has no colour.
        base_colours = value_map(norm(np.nan_to_num(values[body_ids], nan=low,
                                                    posinf=high, neginf=low)))[:, :3]
    else:
        palette = np.asarray(colormaps[_BODY_COLOUR_MAP].colors)[:, :3]
        # Greys would read as unpainted bodies or as the axes panes.
        palette = palette[np.ptp(palette, axis=1) > 0.05]
        base_colours = palette[(body_ids * _BODY_COLOUR_STRIDE) % len(palette)]
    base_colours = np.where(grey[:, None], np.asarray(_MUTED_GREY)[None, :], base_colours)

    plane_triangles = _tile_planes(planes, where)
    all_corners = np.concatenate([triangles, plane_triangles]).reshape(-1, 3)
    lower = all_corners.min(axis=0)
    upper = all_corners.max(axis=0)
    if walls_box is not None:
        wall_lower = np.asarray(walls_box[0], dtype=np.float64).reshape(3)
        wall_upper = np.asarray(walls_box[1], dtype=np.float64).reshape(3)
        lower = np.minimum(lower, wall_lower)
        upper = np.maximum(upper, wall_upper)
    extents = upper - lower
    # A flat layer would give a zero-height box; keep a sliver so the aspect stays defined.
    extents = np.maximum(extents, 1e-3 * extents.max() if extents.max() > 0 else 1.0)
    centre = 0.5 * (lower + upper)
    lower, upper = centre - 0.5 * extents, centre + 0.5 * extents

    intensity = _lambert_intensity(triangles, view)
    face_colours = np.ones((len(triangles) + len(plane_triangles), 4))
    face_colours[:len(triangles), :3] = np.clip(base_colours * intensity[:, None], 0.0, 1.0)
    face_colours[len(triangles):] = _PLANE_RGBA
    # Edges in the face colour hide the hairline seams that antialiasing leaves between
    # neighbouring triangles; plane tiles get none, or their overlapping translucent edges would
    # draw a grid.
    edge_colours = face_colours.copy()
    edge_colours[len(triangles):, 3] = 0.0

    width_px, height_px = size_px
    figure = plt.figure(figsize=(width_px / _DOTS_PER_INCH, height_px / _DOTS_PER_INCH),
                        dpi=_DOTS_PER_INCH)
    try:
        has_colour_bar = values is not None
        # Part of the figure (fractions: left, bottom, right, top) that the 3D axes may fill;
        # the rest holds the title and the colour bar.
        region = (0.01, 0.01, 0.85 if has_colour_bar else 0.99, 0.93 if title else 0.99)
        axes = figure.add_axes([region[0], region[1], region[2] - region[0], region[3] - region[1]],
                               projection="3d")
        axes.set_xlim(lower[0], upper[0])
        axes.set_ylim(lower[1], upper[1])
        axes.set_zlim(lower[2], upper[2])
        axes.set_box_aspect(extents)
        axes.view_init(elev=view[0], azim=view[1])
        axes.set_xlabel("x (m)")
        axes.set_ylabel("y (m)")
        # mplot3d turns the z label along the projected axis, which for views from the -x side
        # (azimuth beyond -90 degrees) prints it upside down; keep it upright, reading upwards.
        axes.zaxis.set_rotate_label(False)
        axes.set_zlabel("z (m)", rotation=90)
        most_ticks = int(np.clip(round(width_px / _PIXELS_PER_TICK), *_TICK_COUNT_BOUNDS))
        for axis, extent in zip((axes.xaxis, axes.yaxis, axes.zaxis), extents):
            axis.pane.set_facecolor((0.96, 0.96, 0.96, 1.0))
            # Fewer ticks on short sides, or the labels of a flat layer's z axis overlap.
            tick_count = int(np.clip(round(most_ticks * extent / extents.max()), 2, most_ticks))
            axis.set_major_locator(MaxNLocator(nbins=tick_count))
        # Fit while the axes are still empty: the bodies lie inside the panes, so the fit is
        # the same, and each trial draw stays cheap however many triangles there are.
        _fit_axes_to_region(figure, axes, region)

        # Planes and bodies in one collection, so that their faces are sorted together.
        surfaces = Poly3DCollection(
            np.concatenate([triangles, plane_triangles]),
            facecolors=face_colours,
            edgecolors=edge_colours,
            linewidths=0.2,
            zsort="average",
        )
        axes.add_collection3d(surfaces)
        if walls_box is not None:
            # One artist per edge: mplot3d orders artists by depth, so edges behind the bodies
            # are then drawn behind them instead of across them.
            for edge in _box_edges(wall_lower, wall_upper):
                axes.add_collection3d(Line3DCollection([edge], colors="0.5", linewidths=0.7))
        for artist in axes.collections:
            # The fitted axes square may be smaller than the drawn box; never crop the bodies.
            artist.set_clip_on(False)

        if title:
            figure.suptitle(title, y=0.985)
        if has_colour_bar:
            colour_bar_axes = figure.add_axes([0.88, 0.2, 0.022, 0.6])
            colour_bar = figure.colorbar(
                ScalarMappable(norm=norm, cmap=value_map), cax=colour_bar_axes,
                extend=colour_bar_extend,
            )
            colour_bar.set_label(value_label)
        with _atomic_target(path) as temporary:
            figure.savefig(temporary, format="png", dpi=_DOTS_PER_INCH)
    finally:
        plt.close(figure)
    return path


def _tile_planes(planes, where: str) -> np.ndarray:
    """Triangles (n, 3, 3) of the planar quadrilaterals ``planes`` cut into a grid of tiles."""
    if planes is None or len(planes) == 0:
        return np.zeros((0, 3, 3))
    tiles = []
    for k, plane in enumerate(planes):
        corners = np.asarray(plane, dtype=np.float64)
        if corners.shape != (4, 3) or not np.all(np.isfinite(corners)):
            raise CaseFileError(f"{where}: plane {k} has shape {corners.shape}, expected 4 finite "
                                "corners (4, 3) in order around its edge.")
        sides = (np.linalg.norm(corners[1] - corners[0]), np.linalg.norm(corners[3] - corners[0]))
        longest = max(sides) if max(sides) > 0 else 1.0
        counts = [max(1, int(round(_PLANE_TILES * side / longest))) for side in sides]
        u = np.linspace(0.0, 1.0, counts[0] + 1)
        v = np.linspace(0.0, 1.0, counts[1] + 1)
        # Bilinear map of the unit square onto the quadrilateral, grid points (len(u), len(v), 3).
        uu, vv = u[:, None, None], v[None, :, None]
        grid = ((1 - uu) * (1 - vv) * corners[0] + uu * (1 - vv) * corners[1]
                + uu * vv * corners[2] + (1 - uu) * vv * corners[3])
        a, b = grid[:-1, :-1].reshape(-1, 3), grid[1:, :-1].reshape(-1, 3)
        c, d = grid[1:, 1:].reshape(-1, 3), grid[:-1, 1:].reshape(-1, 3)
        tiles.append(np.stack([a, b, c], axis=1))
        tiles.append(np.stack([a, c, d], axis=1))
    return np.concatenate(tiles)


def bodies_to_draw(fixed, *, show_fixed: bool) -> tuple[np.ndarray, np.ndarray, str]:
    """Which bodies a picture of a run draws, which of those in grey, and how to name them.

    Parameters
    ----------
    fixed : array_like of bool, shape (n_bodies,)
        Whether each body is held fixed.
    show_fixed : bool
        Draw the fixed bodies in grey (as context) instead of leaving them out. When every body
        is fixed (a finished underlayer) all are drawn in colour either way.

    Returns
    -------
    drawn, grey : numpy.ndarray of bool, shape (n_bodies,)
    description : str
        The bodies as a title counts them, free and fixed separately, e.g. ``"25 free bodies,
        135 fixed bodies (grey)"``.

    Examples
    --------
    >>> drawn, grey, text = bodies_to_draw([True, False, False], show_fixed=False)
    >>> drawn.tolist(), grey.tolist(), text
    ([False, True, True], [False, False, False], '2 free bodies (1 fixed body not drawn)')
    """
    fixed = np.asarray(fixed, dtype=bool).reshape(-1)
    n_fixed = int(fixed.sum())
    n_free = len(fixed) - n_fixed

    def count(number, what=""):
        return " ".join(filter(None, (str(number), what, "body" if number == 1 else "bodies")))

    everything = np.ones(len(fixed), dtype=bool)
    if n_fixed == 0:
        return everything, ~everything, count(n_free)
    if n_free == 0:
        return everything, ~everything, count(n_fixed, "fixed")
    if show_fixed:
        return everything, fixed.copy(), f"{count(n_free, 'free')}, {count(n_fixed, 'fixed')} (grey)"
    return ~fixed, ~everything, f"{count(n_free, 'free')} ({count(n_fixed, 'fixed')} not drawn)"


def _fit_axes_to_region(figure, axes, region: tuple[float, float, float, float]) -> None:
    """Move and scale 3D axes so that what they draw (panes, ticks, labels) fills ``region``.

    mplot3d centres a square viewport in the axes rectangle and leaves wide margins around the
    projected box, most of all for flat scenes. Everything in the viewport scales with its size,
    so mapping the drawn extent onto the region is a scale and a shift of the viewport; tick
    labels keep their font size, hence a few passes.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
    axes : mpl_toolkits.mplot3d.Axes3D
    region : (float, float, float, float)
        Left, bottom, right and top of the target area, as fractions of the figure.
    """
    from matplotlib.transforms import Bbox
    from mpl_toolkits.mplot3d import proj3d

    width_px, height_px = figure.canvas.get_width_height()
    left, bottom = region[0] * width_px, region[1] * height_px
    right, top = region[2] * width_px, region[3] * height_px
    for _ in range(3):
        figure.canvas.draw()
        renderer = figure.canvas.get_renderer()
        # Not axes.get_tightbbox: it counts the invisible 2D frame, i.e. the whole viewport.
        corners = np.array(
            [[limits[(k >> axis) & 1] for axis, limits in enumerate(
                (axes.get_xlim(), axes.get_ylim(), axes.get_zlim()))] for k in range(8)]
        )
        projected_x, projected_y, _ = proj3d.proj_transform(*corners.T, axes.get_proj())
        box_pixels = axes.transData.transform(np.column_stack([projected_x, projected_y]))
        drawn = Bbox.union(
            [Bbox([box_pixels.min(axis=0), box_pixels.max(axis=0)])]
            + [axis.get_tightbbox(renderer) for axis in (axes.xaxis, axes.yaxis, axes.zaxis)]
        )
        viewport = axes.get_position().transformed(figure.transFigure)
        scale = min((right - left) / drawn.width, (top - bottom) / drawn.height)
        new_x0 = 0.5 * (left + right) + scale * (viewport.x0 - 0.5 * (drawn.x0 + drawn.x1))
        new_y0 = 0.5 * (bottom + top) + scale * (viewport.y0 - 0.5 * (drawn.y0 + drawn.y1))
        axes.set_position([new_x0 / width_px, new_y0 / height_px,
                           scale * viewport.width / width_px, scale * viewport.height / height_px])
