"""Joint elements (``riprap.deformable.joints``): the exploded mesh and its joints, the softening
curve, and bad joint input refused by name."""
import numpy as np
import pytest

from riprap.deformable.joints import (SOFTENING_AREA, FracturingBody, JointMaterial, explode_mesh,
                                     locality_order, slot_joint_rows)
from riprap.deformable.kernels.joints import (SOFTENING_A, SOFTENING_B, SOFTENING_C,
                                               gather_joint_forces, softening)
from riprap.deformable.material import ElasticMaterial
from riprap.errors import CaseFileError
from riprap.geometry.structured import box_mesh

GOOD = dict(tensile_strength=3e6, cohesion=6e6, friction_angle=30.0, fracture_energy_mode_i=100.0,
            fracture_energy_mode_ii=1000.0, joint_penalty=3e11)


def test_every_shared_face_gets_one_joint_with_its_nodes_paired():
    nodes, tets = box_mesh((0.2, 0.05, 0.05), (4, 2, 2))
    new_nodes, new_tets, joints, joint_tets, face_joint, original, glued = explode_mesh(nodes, tets)
    assert new_nodes.shape == (4 * len(tets), 3) and new_tets.shape == tets.shape
    # 96 tets, 384 faces, 80 on the box's surface: 152 shared
    assert len(joints) == (4 * len(tets) - 80) // 2 == 152
    assert np.array_equal(new_nodes[joints[:, :3]], new_nodes[joints[:, 3:]])
    assert np.array_equal(original[joints[:, :3]], original[joints[:, 3:]])
    corners = new_nodes[joints[:, :3]]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = corners.mean(axis=1) - new_nodes[new_tets[joint_tets[:, 0]]].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", normal, outward) > 0)
    # each tet's nodes are its own
    assert np.array_equal(new_tets.ravel(), np.arange(new_nodes.shape[0]))
    assert len(glued) == 0 and (face_joint == -1).sum() == 80 and (face_joint >= 0).sum() == 304


def test_joints_only_in_a_region_keep_the_rest_of_the_mesh_whole():
    """Cracking only in the half x > 0.1 of a bar: joints between its tets only, the others share
    their nodes, and a tet beside the region shares nodes with the region's tets only where no
    joint separates them."""
    nodes, tets = box_mesh((0.2, 0.05, 0.05), (4, 2, 2))
    centres = nodes[tets].mean(axis=1)
    cracking = centres[:, 0] > 0.1
    split = explode_mesh(nodes, tets, cracking)
    both = cracking[split.joint_tets].all(axis=1)
    # 48 tets in the half, 48 of their faces on its surface (the section at x = 0.1 included)
    assert both.all() and len(split.joints) == (4 * cracking.sum() - 48) // 2
    assert np.array_equal(split.nodes[split.joints[:, :3]], split.nodes[split.joints[:, 3:]])
    # the whole half keeps one copy of each of its nodes (the section at x = 0.1 included)
    whole = np.unique(split.tets[~cracking])
    assert len(whole) == len(np.unique(tets[~cracking]))
    # a body on it: one piece, its mass that of the solid bar
    body = FracturingBody(nodes, tets, ElasticMaterial(density=2400.0), JointMaterial(**GOOD),
                          cracking=cracking)
    assert len(np.unique(body.fragments())) == 1
    assert body.mass == pytest.approx(2400.0 * 0.2 * 0.05 * 0.05)
    body.joint_broken[:] = True
    table = body.fragment_table()
    # every tet of the cracking half a fragment of its own but the 8 glued by a face to the other
    # half, which stay with it
    held = np.setdiff1d(np.unique(split.glued_tets), np.flatnonzero(~cracking))
    assert len(held) == 8
    assert len(table["mass"]) == cracking.sum() - 8 + 1
    assert table["mass_fraction"][0] == pytest.approx((48 + 8) / 96)
    assert table["mass"].sum() == pytest.approx(body.mass)


@pytest.mark.parametrize("cracking_half", [False, True])
def test_every_joint_force_reaches_its_own_node(cracking_half):
    """Each joint vertex's force, in its row 6 j + k of the buffer and summed per node over the
    rows that the table (``slot_joint_rows``) gives for the faces at the node's (tet, corner)
    slots, is the same as adding the forces one by one: every joint vertex is named once, at the
    slot of its own tet's corner, on its own face's column. With a cracking region, the nodes at
    its edge are shared by several glued tets."""
    nodes, tets = box_mesh((0.2, 0.05, 0.05), (4, 2, 2))
    cracking = nodes[tets].mean(axis=1)[:, 0] > 0.1 if cracking_half else None
    split = explode_mesh(nodes, tets, cracking)
    n = len(split.joints)
    table = slot_joint_rows(split.tets, split.joints, split.joint_tets, split.face_joint)
    named = table[table < 6 * n]
    assert np.array_equal(np.sort(named), np.arange(6 * n))        # each joint vertex once
    slot, column = np.nonzero(table < 6 * n)
    joint, vertex = table[slot, column] // 6, table[slot, column] % 6
    tet, corner = slot // 4, slot % 4
    assert np.array_equal(tet, split.joint_tets[joint, vertex // 3])     # its own side's tet
    assert np.array_equal(split.tets[tet, corner], split.joints[joint, vertex])
    face = column + (column >= corner)                # the faces at corner c: f != c, in order
    assert np.array_equal(split.face_joint[tet, face], joint)
    forces = np.random.default_rng(3).normal(size=(len(split.joints), 6, 3))
    buffer = np.zeros((6 * n + 1, 3))
    buffer[:-1] = forces.reshape(-1, 3)
    expected = np.zeros((len(split.nodes), 3))
    np.add.at(expected, split.joints.ravel(), forces.reshape(-1, 3))
    offsets = np.r_[0, np.cumsum(np.bincount(split.tets.ravel(), minlength=len(split.nodes)))]
    node_slots = np.argsort(split.tets.ravel(), kind="stable")
    summed = np.zeros_like(expected)
    gather_joint_forces(buffer, offsets.astype(np.int64), node_slots.astype(np.int64), table,
                        summed)
    assert (np.bincount(split.tets.ravel()).max() > 1) == cracking_half
    assert np.allclose(summed, expected, rtol=0, atol=1e-12)


def test_a_fracturing_body_numbers_neighbouring_tets_near_each_other():
    """``locality_order`` is a permutation of the tets that brings the two tets of every joint
    closer in number than a random order does (the threaded loop's cache reuse rests on it), and
    a fracturing body keeps its joints in the order of their first, lower tet. The body is the
    same: its mass and its set of tets are unchanged."""
    nodes, tets = box_mesh((0.4, 0.1, 0.1), (16, 4, 4))
    shuffled = tets[np.random.default_rng(5).permutation(len(tets))]
    order = locality_order(shuffled)
    assert np.array_equal(np.sort(order), np.arange(len(tets)))
    before = explode_mesh(nodes, shuffled).joint_tets
    after = explode_mesh(nodes, shuffled[order]).joint_tets
    assert np.median(np.abs(np.diff(after, axis=1))) < 0.2 * np.median(np.abs(np.diff(before, axis=1)))
    body = FracturingBody(nodes, shuffled, ElasticMaterial(density=2400.0), JointMaterial(**GOOD))
    first = body.joint_tets[:, 0]
    assert np.all(first < body.joint_tets[:, 1]) and np.all(np.diff(first) >= 0)
    assert body.mass == pytest.approx(2400.0 * 0.4 * 0.1 * 0.1, rel=1e-12)
    assert (sorted(map(tuple, np.sort(body.original_tets, axis=1)))
            == sorted(map(tuple, np.sort(shuffled, axis=1))))


def test_the_softening_curve_falls_from_one_to_zero():
    damage = np.linspace(0.0, 1.0, 101)
    z = np.array([softening(d) for d in damage])
    assert z[0] == 1.0 and z[-1] == 0.0
    assert np.all(np.diff(z) <= 0.0)
    # the kernel's exponential is a polynomial (so that the joints' law runs on vector
    # registers): Hordijk's curve with numpy's exp, to rounding
    a, b, c = SOFTENING_A, SOFTENING_B, SOFTENING_C
    closed_form = ((1.0 - (a + b - 1.0) / (a + b) * np.exp(damage * (a + c * b) / ((a + b) * (1.0 - a - b))))
                   * (a * (1.0 - damage) + b * (1.0 - damage) ** c))
    assert np.max(np.abs(z - closed_form)) < 1e-14
    assert SOFTENING_AREA == pytest.approx(0.3863, abs=1e-4)


@pytest.mark.parametrize("key, value", [("tensile_strength", 0.0), ("cohesion", -1.0),
                                        ("fracture_energy_mode_i", 0.0),
                                        ("fracture_energy_mode_ii", float("nan")),
                                        ("joint_penalty", -3e11), ("friction_angle", 90.0)])
def test_bad_joint_input_is_refused_by_name(key, value):
    with pytest.raises(CaseFileError, match=key):
        JointMaterial(**{**GOOD, key: value})


def test_a_fracturing_body_needs_a_joint_material():
    nodes, tets = box_mesh((0.1, 0.1, 0.1), (1, 1, 1))
    with pytest.raises(CaseFileError, match="joint_material"):
        FracturingBody(nodes, tets, ElasticMaterial(), {"tensile_strength": 3e6})


def test_an_unloaded_body_keeps_its_joints_and_its_shape():
    nodes, tets = box_mesh((0.1, 0.1, 0.1), (2, 2, 2))
    body = FracturingBody(nodes, tets, ElasticMaterial(), JointMaterial(**GOOD))
    body.step(200)
    assert not body.joint_broken.any() and body.joint_damage.max() == 0.0
    assert np.abs(body.positions - body.elements.reference_nodes).max() < 1e-12
    assert len(np.unique(body.fragments())) == 1


@pytest.mark.parametrize("friction_angle", [0.0, 30.0])
def test_a_broken_joint_pushes_slid_faces_apart_without_turning_them(friction_angle):
    """Two halves of a block cut by broken joints, one slid along the cut by 0.4 joint sizes and
    pressed 10 micrometres into the other: the joints push them apart (a compressive force on
    each half, across the cut), and the forces on all nodes sum to nothing and turn nothing:
    sum f = 0 and sum x x f = 0 to round-off. (The intact joint's pair, applied at each face's own
    point, would make a couple of the slip times the force.) With friction (30 degrees; the
    anchors at the faces' first place, so it slides) the crack's faces also resist the slip with
    tan(phi) times the push, and the only couple is that friction's across the 10 micrometres
    between the faces: |sum x x f| = |f_t| 1e-5 m. Slid past the faces (slip above h): no force
    across the cut."""
    nodes, tets = box_mesh((0.2, 0.1, 0.1), (2, 1, 1))
    joints = JointMaterial(**dict(GOOD, friction_angle=friction_angle))
    body = FracturingBody(nodes, tets, ElasticMaterial(density=2400.0), joints)
    body.joint_broken[:] = True
    centres = body.positions[body.elements.elements].mean(axis=1)
    right = np.zeros(len(body.positions), dtype=bool)
    right[body.elements.elements[centres[:, 0] > 0.1].ravel()] = True
    # only the joints across the cut at x = 0.1 matter: the rest stay at zero opening
    size = body.joint_sizes.mean()
    depth = 1e-5
    for slip, pushed in ((0.4 * size, True), (1.5 * size, False)):
        body.positions[:] = body.elements.reference_nodes
        body.positions[right] += [-depth, slip, 0.0]
        body.joint_friction_anchor[:] = 0.0
        forces = body.joint_forces()
        across = forces[right, 0].sum()
        if pushed:
            assert across > 0.0, "the slid half is pushed back out of the cut"
            scale = np.abs(forces).max()
            assert np.abs(forces.sum(axis=0)).max() < 1e-9 * scale
            along = forces[right, 1].sum()
            tan_phi = np.tan(np.radians(friction_angle))
            assert along == pytest.approx(-tan_phi * across, rel=1e-9, abs=1e-9 * scale)
            torque = np.cross(body.positions, forces).sum(axis=0)
            assert np.abs(torque[:2]).max() < 1e-9 * scale * 0.2
            assert abs(torque[2]) == pytest.approx(abs(along) * depth, rel=1e-6,
                                                   abs=1e-9 * scale * 0.2)
        else:
            # (round-off openings of the joints inside the halves aside)
            assert np.abs(forces[right]).max() < 1e-9 * scale


def test_a_broken_joint_whose_faces_slid_apart_or_sank_in_lets_go_for_good():
    """Broken joints across a cut are released once their faces no longer face each other: slid
    by more than the joint's size, or pressed deeper than 1 % of it into each other (a penalty
    that deep would press with p / 100: the faces got there some other way). Released, they push
    no more, even where the faces come back to face each other 10 micrometres deep (which, never
    released, they push apart: the test above)."""
    nodes, tets = box_mesh((0.2, 0.1, 0.1), (2, 1, 1))
    centres_x = None
    for first_move in ("slide", "sink"):
        body = FracturingBody(nodes, tets, ElasticMaterial(density=2400.0), JointMaterial(**GOOD))
        body.joint_broken[:] = True
        if centres_x is None:
            centres_x = body.positions[body.elements.elements].mean(axis=1)[:, 0]
        right = np.zeros(len(body.positions), dtype=bool)
        right[body.elements.elements[centres_x > 0.1].ravel()] = True
        cut = body.joint_tets
        across = (centres_x[cut[:, 0]] > 0.1) != (centres_x[cut[:, 1]] > 0.1)
        size = body.joint_sizes[across].min()
        move = [-1e-5, 1.5 * size, 0.0] if first_move == "slide" else [-0.05 * size, 0.0, 0.0]
        body.positions[right] += move
        body.joint_forces()
        assert body.joint_released[across].all() and not body.joint_released[~across].any()
        body.positions[:] = body.elements.reference_nodes
        body.positions[right] += [-1e-5, 0.4 * size, 0.0]
        forces = body.joint_forces()
        assert np.abs(forces[right, 0].sum()) < 1e-6, first_move


def _cut_block():
    """A block of two 0.1 m cubes whose joints across the cut at x = 0.1 are the only ones that
    move: the right cube is moved as a rigid piece."""
    nodes, tets = box_mesh((0.2, 0.1, 0.1), (2, 1, 1))
    body = FracturingBody(nodes, tets, ElasticMaterial(density=2400.0), JointMaterial(**GOOD))
    centres_x = body.positions[body.elements.elements].mean(axis=1)[:, 0]
    right = np.zeros(len(body.positions), dtype=bool)
    right[body.elements.elements[centres_x > 0.1].ravel()] = True
    return body, right


def test_joint_friction_dissipates_on_a_closed_path_and_gives_nothing_back():
    """The right cube of a cut block is slid along the cut by U (faces free), pressed in by O,
    slid back and let go: a closed path of its nodes. The joints' cohesion is elastic there
    (U below its peak slip 2 h c / p) and the normal penalty too, so the work the joints do on the
    cube over the path is minus what their friction dissipated: sliding back under the normal
    stress sigma = p O / h, the friction (a spring p / h from its anchor, no stronger than
    tan(phi) sigma) sticks over u = tan(phi) O, then slides over U - u; letting go releases its
    spring's energy. Dissipated: tan(phi) sigma A (U - u / 2), A = 0.01 m^2 (Coulomb friction
    with an elastic stick range, e.g. Wriggers, Computational Contact Mechanics, 2006, sec. 5.2).
    Within 2 %. (Munjiza's law with f_s = c - tan(phi) sigma inside the rising curve, riprap's
    before this test, gives the cube energy on this path: its shear traction is higher on the way
    back, by (p U^3 / 6 h)(1 / s_p(0) - 1 / s_p(sigma)) A = 0.009 J, s_p = 2 h f_s / p.)"""
    body, right = _cut_block()
    material = JointMaterial(**GOOD)
    p, tan_phi = material.joint_penalty, np.tan(np.radians(material.friction_angle))
    # the joints across the cut: each face half of a square, h = (0.1 + 0.1 + 0.1 sqrt 2) / 3
    across = right[body.joints[:, 0]] != right[body.joints[:, 3]]
    assert across.sum() == 2
    h = body.joint_sizes[across][0]
    assert h == pytest.approx(0.1 * (2 + np.sqrt(2)) / 3)
    slide, press = 3e-6, 2e-6
    assert slide < 2 * h * material.cohesion / p
    corners = [(0.0, 0.0), (0.0, slide), (-press, slide), (-press, 0.0), (0.0, 0.0)]
    work = 0.0
    forces = body.joint_forces()
    for (x0, y0), (x1, y1) in zip(corners[:-1], corners[1:]):
        for t in np.linspace(0.0, 1.0, 401)[1:]:
            move = np.array([x0 + t * (x1 - x0), y0 + t * (y1 - y0), 0.0])
            before = body.positions[right].copy()
            body.positions[:] = body.elements.reference_nodes
            body.positions[right] += move
            new_forces = body.joint_forces()
            step = body.positions[right] - before
            work += 0.5 * np.sum((forces[right] + new_forces[right]) * step)
            forces = new_forces
    assert not body.joint_broken.any() and body.joint_damage.max() == 0.0
    sigma = p * press / h
    stick = tan_phi * press
    dissipated = tan_phi * sigma * 0.01 * (slide - 0.5 * stick)
    assert -work == pytest.approx(dissipated, rel=0.02)


def test_joint_friction_turns_with_the_joint():
    """A pressed, slid cut block turned as a whole by 30 degrees: its joints' forces turn with it
    (the friction anchors sit in the joint's own plane, so a rigid turn is no slip)."""
    body, right = _cut_block()
    body.positions[right] += [-2e-6, 3e-6, 0.0]
    body.joint_forces()
    body.positions[right] += [0.0, -1e-6, 0.0]        # back a little: the friction sticks
    slid = body.positions.copy()
    forces = body.joint_forces()
    assert np.abs(forces[right, 1].sum()) > 0.0
    angle = np.radians(30.0)
    turn = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0],
                     [0.0, 0.0, 1.0]])
    body.positions[:] = slid @ turn.T
    turned = body.joint_forces()
    assert np.abs(turned - forces @ turn.T).max() < 1e-6 * np.abs(forces).max()
