"""Damage counting (``riprap.analysis.damage``) on constructed cases with known answers (issue 15):
units moved by hand by known amounts, rotation records with a known number of rocks, and rock
profiles with a known eroded area.

Sources: N_od = displaced units per D_n of width and S = A_e / D_n50^2 (Van der Meer 1988;
Broderick 1983), exact for the constructed cases (tolerance round-off)."""
import numpy as np
import pytest

from riprap.analysis.damage import (damage_level_s, damage_number_nod, displaced_units,
                                    eroded_area, profile_from_surfaces, rocking_events,
                                    surface_profile)
from riprap.analysis.displacements import unit_displacements
from riprap.errors import CaseFileError


def test_units_moved_by_hand_give_their_nod():
    dn, width = 0.5, 4.0
    reference = np.array([[x, y, 0.0] for x in (0.0, 1.0) for y in (0.5, 1.5, 2.5, 3.5)])
    moved = reference.copy()
    moved[1] += (0.0, 0.0, -0.6)          # 1.2 Dn down the face: displaced
    moved[5] += (0.3, 0.4, 0.0)           # 1.0 Dn exactly: not more than the threshold
    moved[6] += (0.8, 0.0, 0.6)           # 2 Dn
    moved[7] += (0.1, 0.0, 0.0)           # 0.2 Dn: rocked in place
    eye = np.repeat(np.eye(3)[None], len(reference), axis=0)
    over_dn = unit_displacements(moved, eye, reference, eye, nominal_diameter=dn)["displacement_over_dn"]
    displaced = displaced_units(over_dn, 1.0)
    assert list(displaced) == [1, 6]
    assert damage_number_nod(len(displaced), width, dn) == pytest.approx(2 / 8)
    assert list(displaced_units(over_dn, 0.1)) == [1, 5, 6, 7]


def test_rocking_events_count_returns_through_half_the_angle():
    t = np.linspace(0.0, 10.0, 1001)
    rocking = 3.0 * np.abs(np.sin(np.pi * t / 2.0))       # five excursions to 3 degrees and back
    creeping = np.linspace(0.0, 10.0, t.size)             # turns once, never comes back
    noisy = 1.9 + 0.2 * np.sin(40.0 * t)                  # about 2 degrees, never below 1
    events = rocking_events(np.column_stack([rocking, creeping, noisy]), rocking_angle=2.0)
    assert list(events) == [5, 0, 0]


def test_eroded_area_of_a_known_profile():
    dn = 0.2
    x = np.linspace(0.0, 4.0, 401)
    before = 0.5 * x                                      # a 1:2 face
    after = before - np.where((x > 1.0) & (x < 2.0), 0.1 * np.sin(np.pi * (x - 1.0)), 0.0)
    after[x > 2.5] += 0.05                                # deposited lower down: not erosion
    area = eroded_area(before, after, x[1] - x[0])
    assert area == pytest.approx(0.2 / np.pi, rel=1e-4)   # integral of 0.1 sin over one unit
    assert damage_level_s(area, dn) == pytest.approx(0.2 / np.pi / 0.04, rel=1e-4)


def test_profile_is_the_upper_envelope_averaged_over_strips():
    points = np.array([[0.5, 0.1, 1.0], [0.6, 0.2, 2.0],      # strip 0: top 2
                       [0.5, 1.1, 4.0],                      # strip 1: top 4
                       [1.5, 0.1, 0.5]])                     # second bin, strip 0 only
    profile = surface_profile(points, x_edges=[0.0, 1.0, 2.0, 3.0], y_edges=[0.0, 1.0, 2.0])
    assert profile[0] == pytest.approx(3.0) and profile[1] == pytest.approx(0.5)
    assert np.isnan(profile[2])
    with pytest.raises(CaseFileError, match="threshold must be > 0"):
        displaced_units([1.0], 0.0)


def _cube_triangles(lower, size=1.0):
    from riprap.geometry import shapes

    mesh = shapes.box(lengths=(size, size, size))
    nodes = mesh.nodes - mesh.nodes.min(axis=0) + np.asarray(lower, dtype=float)
    return nodes[mesh.boundary_faces()]


def test_a_unit_taken_out_of_a_two_layer_stack_erodes_its_cross_section():
    """Two layers of four unit cubes along x (1 m wide flume); taking the top cube over
    x = 1..2 away lowers the surface there from 2 m to 1 m: A_e = 1 m^2 exactly, S = 1 / D_n^2.
    The profile is read from the cubes' surface triangles; the mesh nodes' highest points per
    bin would still see the neighbours' corners at x = 1 and 2."""
    spacing = 0.25
    xs = np.arange(0.5 * spacing, 4.0, spacing)
    ys = np.arange(0.5 * spacing, 1.0, spacing)
    cubes = [_cube_triangles((i, 0.0, layer)) for layer in (0.0, 1.0) for i in range(4)]
    before = profile_from_surfaces(np.concatenate(cubes), xs, ys)
    assert np.allclose(before, 2.0)
    after = profile_from_surfaces(np.concatenate(cubes[:5] + cubes[6:]), xs, ys)
    assert np.allclose(after, np.where((xs > 1.0) & (xs < 2.0), 1.0, 2.0))
    area = eroded_area(before, after, spacing)
    assert area == pytest.approx(1.0, abs=1e-12)
    assert damage_level_s(area, 0.8) == pytest.approx(1.0 / 0.64)
    outside = profile_from_surfaces(np.concatenate(cubes), np.array([5.0, 6.0]), ys)
    assert np.all(np.isnan(outside))
