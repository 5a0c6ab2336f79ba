"""Momentum transport consistent with the mass transport (riprap.fluid.kernels.momentum).

The property that keeps a 1:1000 density jump stable (Rudman 1998): when the momentum of each face
control volume moves with exactly the mass fluxes that move its density, a uniform velocity stays
uniform whatever the fluxes and densities. Checked with random mass fluxes, random densities from
1 to 1000 kg/m^3 and no viscosity or gravity: every component keeps the velocity to 1e-12
relative (round-off; measured 3e-14). And the mass of a control volume changes by exactly its net
mass flux.
"""
import numpy as np
import pytest

from riprap.fluid.kernels.momentum import FREE_SLIP, NO_SLIP, OPEN, transport_component


@pytest.mark.parametrize("two_dimensional", [False, True])
def test_a_uniform_velocity_stays_uniform_across_any_density_jump(two_dimensional):
    rng = np.random.default_rng(1)
    nx, ny, nz = (8, 1, 7) if two_dimensional else (8, 6, 7)
    shapes = [(nx + 1, ny, nz), (nx, ny + 1, nz), (nx, ny, nz + 1)]
    masses = [rng.normal(size=shape) for shape in shapes]
    if two_dimensional:
        masses[1][:] = 0.0
    velocities = [np.full(shape, 0.3) for shape in shapes]
    density = rng.uniform(1.0, 1000.0, size=(nx, ny, nz))
    viscosity = np.zeros((nx, ny, nz))
    sides = np.array([NO_SLIP, FREE_SLIP, NO_SLIP, NO_SLIP, NO_SLIP, OPEN])
    h, dt, value = 0.1, 0.01, 0.7
    for axis in ((0, 2) if two_dimensional else (0, 1, 2)):
        q = np.full(shapes[axis], value)
        out, new_density = np.empty_like(q), np.empty_like(q)
        transport_component(q, axis, masses[0], masses[1], masses[2], velocities[0], velocities[1],
                            velocities[2], density, viscosity, sides, h, dt, 0.0, two_dimensional,
                            out, new_density)
        assert np.abs(out - value).max() <= 1e-12 * value
        # Interior control volume of the x component at cell pair (2, 3): its new mass is the old
        # one plus the net inflow of the averaged face fluxes.
        if axis == 0:
            i, j, k = 3, min(2, ny - 1), 3
            old = 0.5 * (density[i - 1, j, k] + density[i, j, k])
            inflow = 0.5 * (masses[0][i - 1, j, k] + masses[0][i, j, k]) - 0.5 * (
                masses[0][i, j, k] + masses[0][i + 1, j, k])
            for d in ((2,) if two_dimensional else (1, 2)):
                lower = [i, j, k]
                upper = [i, j, k]
                upper[d] += 1
                for cell in (i - 1, i):
                    low = list(lower)
                    up = list(upper)
                    low[0] = up[0] = cell
                    inflow += 0.5 * (masses[d][tuple(low)] - masses[d][tuple(up)])
            assert new_density[i, j, k] == pytest.approx(old + inflow / h ** 3, rel=1e-12)
