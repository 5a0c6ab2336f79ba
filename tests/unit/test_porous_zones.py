"""Porous zones (``riprap.fluid.porous``, ``plic.advect(porosity=...)``, the friction in
``FluidSolver``): the water in the pores moves at the pore velocity U/n and is conserved as
sum(n f) V; zones cover cells exactly (boxes) or by sub-samples (polygons); the implicit friction
and the pressure's face factor are those of the closure; bad zones are refused naming them."""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.errors import CaseFileError
from riprap.fluid.kernels.plic import advect
from riprap.fluid.porous import PorousMedium, PorousZone


def test_water_front_moves_at_the_pore_velocity_and_pore_water_is_conserved():
    nx, h, dt, speed, n = 80, 0.01, 0.01, 0.2, 0.4
    f = np.zeros((nx, 1, 4))
    f[:10] = 1.0
    porosity = np.full(f.shape, n)
    u = np.full((nx + 1, 1, 4), speed)
    u[0] = u[-1] = 0.0                # walls; cell 0 is refilled every step (the source)
    v, w = np.zeros((nx, 2, 4)), np.zeros((nx, 1, 5))
    before = float((porosity * f).sum())
    inflow = 0.0
    for step in range(10):           # 0.1 s: the front moves U t / n = 0.05 m = 5 cells
        f[0] = 1.0                    # keep feeding water from the left
        before_step = float((porosity * f).sum())
        advect(f, u, v, w, dt, h, step, porosity=porosity)
        inflow += float((porosity * f).sum()) - before_step
    front = np.flatnonzero(f[:, 0, 0] > 0.5).max() + 1
    assert front == 15
    assert abs(float((porosity * f).sum()) - before - inflow) < 1e-12


def test_box_and_polygon_cover_and_face_properties():
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 0.1, 0.5), cells=(10, 1, 5))
    box = PorousZone(porosity=0.4, stone_diameter=0.02, lower=(0.25, 0.0, 0.0), upper=(0.5, 0.1, 0.2))
    cover = box.cover(grid)
    assert cover[2, 0, 0] == pytest.approx(0.5) and cover[3, 0, 1] == pytest.approx(1.0)
    assert cover[4, 0, 2] == 0.0
    triangle = PorousZone(porosity=0.4, stone_diameter=0.02, polygon=((0.0, 0.0), (1.0, 0.0), (0.0, 0.5)))
    area = triangle.cover(grid)[:, 0, :].sum() * 0.01
    assert area == pytest.approx(0.25, rel=0.03)              # 4 x 4 samples per cell
    medium = PorousMedium(grid, [box])
    assert medium.porosity[3, 0, 0] == pytest.approx(0.4)
    assert medium.porosity[2, 0, 0] == pytest.approx(0.7)     # half covered: 1 - 0.5 (1 - 0.4)
    assert medium.face_porosity[0][3, 0, 0] == pytest.approx(0.55)
    linear = 50.0 * 0.6 ** 3 / (0.4 ** 3 * 0.02 ** 2)
    assert medium.linear_coefficient[0][4, 0, 0] == pytest.approx(linear)


def test_friction_and_pressure_factor_follow_the_closure():
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.4, 0.02, 0.2), cells=(20, 1, 10))
    fluid = FluidSolver(grid, surface_tension=0.0, gravity=(0.0, 0.0, 0.0))
    fluid.set_still_water_level(0.2)
    zone = PorousZone(porosity=0.5, stone_diameter=0.01, lower=(0.0, 0.0, 0.0), upper=(0.4, 0.02, 0.2))
    fluid.add_porous_zones([zone])
    fluid.u[1:-1] = 0.05
    dt = 1e-3
    u, v, w, densities = fluid.predict(dt)
    s = 0.5 / 1.34
    rho, mu = fluid.water.density, fluid.water.dynamic_viscosity
    k = s * (50 * 0.5 ** 3 / (0.5 ** 3 * 1e-4) * mu + 2.0 * 0.5 / (0.5 ** 3 * 0.01) * rho * 0.05) / rho
    # a uniform flow has no advection or viscous increment: only the friction acts
    assert u[10, 0, 5] == pytest.approx(0.05 / (1 + dt * k), rel=1e-9)
    betas = fluid._face_coefficients(densities)
    assert betas[0][10, 0, 5] == pytest.approx(s / (1 + dt * k) / densities[0][10, 0, 5], rel=1e-9)


@pytest.mark.parametrize("keys, message", [
    (dict(porosity=1.0, stone_diameter=0.01, lower=(0, 0, 0), upper=(1, 1, 1)), "porosity"),
    (dict(porosity=0.4, stone_diameter=0.0, lower=(0, 0, 0), upper=(1, 1, 1)), "stone_diameter"),
    (dict(porosity=0.4, stone_diameter=0.01), "give a box"),
    (dict(porosity=0.4, stone_diameter=0.01, polygon=((0, 0), (1, 0))), "3 points"),
])
def test_bad_zones_are_refused(keys, message):
    with pytest.raises(CaseFileError, match=message):
        PorousZone(name="core", **keys)
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 0.1, 0.5), cells=(10, 1, 5))
    with pytest.raises(CaseFileError, match="covers no part"):
        PorousMedium(grid, [PorousZone(porosity=0.4, stone_diameter=0.01, lower=(2, 0, 0), upper=(3, 1, 1))])
