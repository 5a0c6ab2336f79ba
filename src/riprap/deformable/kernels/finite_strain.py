"""Compiled kernels of explicit finite-strain tetrahedra: internal forces, the central-difference
update, element stresses and stored energy.

Every element is described by the reference gradients of its shape functions at its integration
points, so F = sum_a x_a (x) grad N_a and the nodal internal force is
f_a = -sum_g w_g P_g grad N_a, with P = J sigma F^-T the first Piola-Kirchhoff stress. The 4-node
tet (one point) has its own kernel because it carries nearly all the work; the 10-node tet uses the
general one. Positions are taken relative to the element's first node (the gradients sum to zero),
which keeps F accurate for bodies far from the origin.

Element forces go to a per-element array first and are summed per node by a second loop over a
node-to-element list, so that both loops run in parallel without atomics.

Constitutive codes (``riprap.deformable.material.CONSTITUTIVE_MODELS``): 0 the seed's eq. 10,
1 Neo-Hookean with lambda ln J, 2 the volumetric-isochoric split.
"""
import math

import types

import numpy as np

from riprap._jit import inline_kernel, kernel, leaf_kernel, parallel_kernel, prange
from riprap.deformable.kernels import contact as contact_kernels
from riprap.deformable.kernels import joints as joint_kernels
from riprap.deformable.kernels.bundles import SurfaceLaws
from riprap.deformable.kernels.slots import joint_slot_sum, node_slot_sum, single_slots_of


@inline_kernel
def kirchhoff_stress(model, mu, lam, kappa, eta,
                     f00, f01, f02, f10, f11, f12, f20, f21, f22,
                     g00, g01, g02, g10, g11, g12, g20, g21, g22):
    """J and the Kirchhoff stress tau = J sigma (6 components xx, yy, zz, xy, yz, zx) for the
    deformation gradient F (f..) and its rate dF/dt (g..); also F's cofactor matrix (F^-T = cof / J).
    Returns (J, t00, t11, t22, t01, t12, t20, c00, c01, c02, c10, c11, c12, c20, c21, c22).

    23 arguments: the material's scalars and the 18 entries of F and dF/dt as scalars, so that the
    inlined law stays in registers (an array per point would be allocated or reference-counted per
    integration point).
    """
    c00 = f11 * f22 - f12 * f21
    c01 = f12 * f20 - f10 * f22
    c02 = f10 * f21 - f11 * f20
    c10 = f02 * f21 - f01 * f22
    c11 = f00 * f22 - f02 * f20
    c12 = f01 * f20 - f00 * f21
    c20 = f01 * f12 - f02 * f11
    c21 = f02 * f10 - f00 * f12
    c22 = f00 * f11 - f01 * f10
    jac = f00 * c00 + f01 * c01 + f02 * c02
    # B = F F^T
    b00 = f00 * f00 + f01 * f01 + f02 * f02
    b11 = f10 * f10 + f11 * f11 + f12 * f12
    b22 = f20 * f20 + f21 * f21 + f22 * f22
    b01 = f00 * f10 + f01 * f11 + f02 * f12
    b12 = f10 * f20 + f11 * f21 + f12 * f22
    b20 = f20 * f00 + f21 * f01 + f22 * f02
    trace_b = b00 + b11 + b22
    if model == 0:
        shear = mu
        iso = -mu + 0.5 * lam * (trace_b - 3.0)
    elif model == 1:
        shear = mu
        log_j = math.log(jac) if jac > 0.0 else -np.inf
        iso = -mu + lam * log_j
    else:
        # J^(-2/3); the sign keeps an inverted element's stress finite until the run stops on it
        scale = mu / np.cbrt(jac * jac) if jac != 0.0 else np.inf
        shear = scale
        iso = 0.5 * kappa * (jac * jac - 1.0) - scale * trace_b / 3.0
    t00 = shear * b00 + iso
    t11 = shear * b11 + iso
    t22 = shear * b22 + iso
    t01 = shear * b01
    t12 = shear * b12
    t20 = shear * b20
    if eta > 0.0:
        # tau_viscous = 2 eta J D, D = sym(dF/dt F^-1) and J F^-1 = cof^T
        l00 = g00 * c00 + g01 * c01 + g02 * c02
        l01 = g00 * c10 + g01 * c11 + g02 * c12
        l02 = g00 * c20 + g01 * c21 + g02 * c22
        l10 = g10 * c00 + g11 * c01 + g12 * c02
        l11 = g10 * c10 + g11 * c11 + g12 * c12
        l12 = g10 * c20 + g11 * c21 + g12 * c22
        l20 = g20 * c00 + g21 * c01 + g22 * c02
        l21 = g20 * c10 + g21 * c11 + g22 * c12
        l22 = g20 * c20 + g21 * c21 + g22 * c22
        t00 += 2.0 * eta * l00
        t11 += 2.0 * eta * l11
        t22 += 2.0 * eta * l22
        t01 += eta * (l01 + l10)
        t12 += eta * (l12 + l21)
        t20 += eta * (l20 + l02)
    return (jac, t00, t11, t22, t01, t12, t20, c00, c01, c02, c10, c11, c12, c20, c21, c22)


@inline_kernel
def point_piola(positions, velocities, nodes, point_gradients, weight, material):
    """J and the first Piola-Kirchhoff stress times ``weight`` (9 components, row-major) at one
    integration point of an element with nodes ``nodes``, shape-function gradients
    ``point_gradients`` (n_local, 3) and ``material`` (model code, mu, lambda, kappa, eta)."""
    n0 = nodes[0]
    f00 = f01 = f02 = f10 = f11 = f12 = f20 = f21 = f22 = 0.0
    g00 = g01 = g02 = g10 = g11 = g12 = g20 = g21 = g22 = 0.0
    for a in range(1, nodes.shape[0]):
        n = nodes[a]
        dx0 = positions[n, 0] - positions[n0, 0]
        dx1 = positions[n, 1] - positions[n0, 1]
        dx2 = positions[n, 2] - positions[n0, 2]
        dv0 = velocities[n, 0] - velocities[n0, 0]
        dv1 = velocities[n, 1] - velocities[n0, 1]
        dv2 = velocities[n, 2] - velocities[n0, 2]
        h0 = point_gradients[a, 0]
        h1 = point_gradients[a, 1]
        h2 = point_gradients[a, 2]
        f00 += dx0 * h0
        f01 += dx0 * h1
        f02 += dx0 * h2
        f10 += dx1 * h0
        f11 += dx1 * h1
        f12 += dx1 * h2
        f20 += dx2 * h0
        f21 += dx2 * h1
        f22 += dx2 * h2
        g00 += dv0 * h0
        g01 += dv0 * h1
        g02 += dv0 * h2
        g10 += dv1 * h0
        g11 += dv1 * h1
        g12 += dv1 * h2
        g20 += dv2 * h0
        g21 += dv2 * h1
        g22 += dv2 * h2
    (jac, t00, t11, t22, t01, t12, t20,
     c00, c01, c02, c10, c11, c12, c20, c21, c22) = kirchhoff_stress(
        int(material[0]), material[1], material[2], material[3], material[4],
        f00, f01, f02, f10, f11, f12, f20, f21, f22, g00, g01, g02, g10, g11, g12, g20, g21, g22)
    # P = tau F^-T = tau cof / J
    s = weight / jac
    return (jac,
            s * (t00 * c00 + t01 * c10 + t20 * c20), s * (t00 * c01 + t01 * c11 + t20 * c21),
            s * (t00 * c02 + t01 * c12 + t20 * c22), s * (t01 * c00 + t11 * c10 + t12 * c20),
            s * (t01 * c01 + t11 * c11 + t12 * c21), s * (t01 * c02 + t11 * c12 + t12 * c22),
            s * (t20 * c00 + t12 * c10 + t22 * c20), s * (t20 * c01 + t12 * c11 + t22 * c21),
            s * (t20 * c02 + t12 * c12 + t22 * c22))


@inline_kernel
def tet4_element(e, positions, velocities, tets, gradients, volumes,
                 materials, element_material, element_forces, jacobians):
    """Internal forces of 4-node tet ``e`` into ``element_forces[e]`` (4, 3) and J into
    ``jacobians[e]``. ``gradients[e]`` (4, 3): the reference gradients of the shape functions,
    ``volumes[e]`` the reference volume."""
    (jac, p00, p01, p02, p10, p11, p12, p20, p21, p22) = point_piola(
        positions, velocities, tets[e], gradients[e], volumes[e], materials[element_material[e]])
    jacobians[e] = jac
    s0 = s1 = s2 = 0.0
    for k in range(1, 4):
        h0 = gradients[e, k, 0]
        h1 = gradients[e, k, 1]
        h2 = gradients[e, k, 2]
        a0 = -(p00 * h0 + p01 * h1 + p02 * h2)
        a1 = -(p10 * h0 + p11 * h1 + p12 * h2)
        a2 = -(p20 * h0 + p21 * h1 + p22 * h2)
        element_forces[e, k, 0] = a0
        element_forces[e, k, 1] = a1
        element_forces[e, k, 2] = a2
        s0 += a0
        s1 += a1
        s2 += a2
    # node 0's gradient is minus the sum of the others'
    element_forces[e, 0, 0] = -s0
    element_forces[e, 0, 1] = -s1
    element_forces[e, 0, 2] = -s2


@inline_kernel
def general_element(e, positions, velocities, elements, gradients, weights,
                    materials, element_material, element_forces, jacobians):
    """Internal forces of element ``e`` with several integration points (the 10-node tet).

    ``gradients[e, g, a]`` is the reference gradient of node a's shape function at point g,
    ``weights[e, g]`` the reference volume that point stands for; ``jacobians[e]`` gets the
    smallest J over the element's points."""
    n_nodes = elements.shape[1]
    for a in range(n_nodes):
        for i in range(3):
            element_forces[e, a, i] = 0.0
    smallest = np.inf
    for g in range(gradients.shape[1]):
        (jac, p00, p01, p02, p10, p11, p12, p20, p21, p22) = point_piola(
            positions, velocities, elements[e], gradients[e, g], weights[e, g],
            materials[element_material[e]])
        smallest = min(smallest, jac)
        for a in range(n_nodes):
            h0 = gradients[e, g, a, 0]
            h1 = gradients[e, g, a, 1]
            h2 = gradients[e, g, a, 2]
            element_forces[e, a, 0] -= p00 * h0 + p01 * h1 + p02 * h2
            element_forces[e, a, 1] -= p10 * h0 + p11 * h1 + p12 * h2
            element_forces[e, a, 2] -= p20 * h0 + p21 * h1 + p22 * h2
    jacobians[e] = smallest


@parallel_kernel
def tet4_element_forces(positions, velocities, tets, gradients, volumes,
                        materials, element_material, element_forces, jacobians):
    """:func:`tet4_element` for every element, in parallel."""
    for e in prange(tets.shape[0]):
        tet4_element(e, positions, velocities, tets, gradients, volumes, materials,
                     element_material, element_forces, jacobians)


#: Blocks of :func:`tet4_and_joint_forces`: each holds the same share of tets and of joints, so
#: that the threads get equal work (a joint costs about twice a tet).
FORCE_BLOCKS = 64


@parallel_kernel
def tet4_and_joint_forces(positions, velocities, tets, gradients, volumes, materials,
                          element_material, element_forces, jacobians, joint_data):
    """:func:`tet4_element` for every element and the joints' forces (``joint_data``:
    :class:`~riprap.deformable.kernels.bundles.JointData`) in one parallel loop: both only read the positions, so one region
    instead of two (each region costs the threads a wake-up)."""
    (joint_nodes, joint_sizes, joint_properties, joint_material, joint_damage, joint_broken,
     joint_buffer, _, joint_released, _, joint_anchors) = joint_data
    n_tets = tets.shape[0]
    n_joints = joint_nodes.shape[0]
    for block in prange(FORCE_BLOCKS):
        # each block its own scratch for the joints (23 kB; 64 small allocations a step)
        scratch = np.empty(joint_kernels.JOINT_SCRATCH_SIZE)
        for e in range(block * n_tets // FORCE_BLOCKS, (block + 1) * n_tets // FORCE_BLOCKS):
            tet4_element(e, positions, velocities, tets, gradients, volumes, materials,
                         element_material, element_forces, jacobians)
        joint_kernels.joint_range(block * n_joints // FORCE_BLOCKS,
                                  (block + 1) * n_joints // FORCE_BLOCKS, positions, joint_nodes,
                                  joint_sizes, joint_properties, joint_material, joint_damage,
                                  joint_broken, joint_released, joint_anchors, joint_buffer,
                                  scratch)


@kernel
def element_forces_serial(positions, velocities, elements, tet4_gradients, gradients, weights,
                          materials, element_material, element_forces, jacobians):
    """Internal forces of every element on one thread (small bodies: no thread start-up)."""
    if elements.shape[1] == 4:
        for e in range(elements.shape[0]):
            tet4_element(e, positions, velocities, elements, tet4_gradients, weights[:, 0],
                         materials, element_material, element_forces, jacobians)
    else:
        for e in range(elements.shape[0]):
            general_element(e, positions, velocities, elements, gradients, weights, materials,
                            element_material, element_forces, jacobians)


@parallel_kernel
def general_element_forces(positions, velocities, elements, gradients, weights,
                           materials, element_material, element_forces, jacobians):
    """:func:`general_element` for every element, in parallel."""
    for e in prange(elements.shape[0]):
        general_element(e, positions, velocities, elements, gradients, weights, materials,
                        element_material, element_forces, jacobians)


@inline_kernel
def update_node(n, ex, ey, ez, jx, jy, jz, positions, velocities, masses, external_forces,
                contact_forces, gravity, mass_damping, constrained, prescribed_velocities,
                first_loaded, first_held, time_step, listed_positions):
    """Central-difference update of node ``n`` (see :func:`central_difference_update`) under the
    elements' force (ex, ey, ez) and the joints' (jx, jy, jz) on it; returns the work of the
    joints' force over the step and the node's squared distance from ``listed_positions`` after
    it.

    20 arguments: inlined per node into both node-update loops, which hand it plain arrays and
    scalars (a bundle would be taken apart per node).
    """
    m = masses[n]
    # nodes before ``first_loaded`` (``first_held``) have no load (no held component): they skip
    # those reads and choices (examples/11's split unit: its node update alone 80 -> 62
    # microseconds; with the same reads made branch-free from a row of zeros it stayed at 80:
    # the cost is the instructions, not the bytes)
    load_x = load_y = load_z = 0.0
    if n >= first_loaded:
        load_x = external_forces[n, 0]
        load_y = external_forces[n, 1]
        load_z = external_forces[n, 2]
    # written out per axis: a helper per axis (inlined) made the one-thread loop 2 to 3 times
    # slower (numba 0.68, this machine), the threaded one not
    before_x = velocities[n, 0]
    before_y = velocities[n, 1]
    before_z = velocities[n, 2]
    velocity_x = before_x + time_step * (load_x + contact_forces[n, 0] + m * gravity[0]
                                         - mass_damping * m * before_x + ex + jx) / m
    velocity_y = before_y + time_step * (load_y + contact_forces[n, 1] + m * gravity[1]
                                         - mass_damping * m * before_y + ey + jy) / m
    velocity_z = before_z + time_step * (load_z + contact_forces[n, 2] + m * gravity[2]
                                         - mass_damping * m * before_z + ez + jz) / m
    if n >= first_held:
        if constrained[n, 0]:
            velocity_x = prescribed_velocities[n, 0]
        if constrained[n, 1]:
            velocity_y = prescribed_velocities[n, 1]
        if constrained[n, 2]:
            velocity_z = prescribed_velocities[n, 2]
    velocities[n, 0] = velocity_x
    velocities[n, 1] = velocity_y
    velocities[n, 2] = velocity_z
    positions[n, 0] += time_step * velocity_x
    positions[n, 1] += time_step * velocity_y
    positions[n, 2] += time_step * velocity_z
    # the trapezoidal rule for the joints' work, exact for a linear spring (the rectangle rule
    # gains k dx^2 / 2 a step: a steady drift while the joints vibrate): this step's force over
    # the intervals on both sides of it, each at its velocity
    wx = (before_x + velocity_x) * jx
    wy = (before_y + velocity_y) * jy
    wz = (before_z + velocity_z) * jz
    work = 0.5 * time_step * (wx + wy + wz)
    mx = positions[n, 0] - listed_positions[n, 0]
    my = positions[n, 1] - listed_positions[n, 1]
    mz = positions[n, 2] - listed_positions[n, 2]
    return work, mx * mx + my * my + mz * mz


def _serial_twin(function, name):
    """A copy of ``function`` under its own ``name``, to be compiled on one thread as the twin of
    its parallel kernel: one body for both (``prange`` is ``range`` outside a parallel kernel).
    The name keeps the two apart in numba's on-disk cache, which is keyed by a function's name and
    its argument types, not by the compile options."""
    twin = types.FunctionType(function.__code__, function.__globals__, name,
                              function.__defaults__, function.__closure__)
    twin.__qualname__ = name
    twin.__module__ = function.__module__
    twin.__doc__ = function.__doc__
    return twin


def _central_difference_update(positions, velocities, element_forces, node_offsets, node_slots,
                               single_slots, masses, external_forces, contact_forces, gravity,
                               mass_damping, constrained, prescribed_velocities, first_loaded,
                               first_held, time_step, listed_positions):
    """Sum the element forces at every node, add loads, gravity and mass-proportional damping,
    and advance the half-step velocity and the position (central difference / leapfrog).
    Returns the largest squared distance of a node from ``listed_positions`` after it (pass
    ``positions`` itself where none is wanted).

    ``node_slots[node_offsets[n]:node_offsets[n + 1]]`` lists the flat (element, local node)
    entries of ``element_forces`` that act on node n; ``single_slots[n]`` names its one entry
    where it has only one, else -1 (``slots.single_slots_of``). Components flagged in
    ``constrained`` take ``prescribed_velocities`` instead.

    17 arguments: the arrays of ``NodeState`` and the step's settings one by one, because this
    body is also the parallel kernel's, whose threads take plain arrays.
    ``central_difference_update_serial``: the same on one thread (small bodies: no thread
    start-up), compiled without reference counts (``leaf_kernel``): numba took references to the
    arrays read in ``update_node``'s branches, per node."""
    flat = element_forces.reshape((-1, 3))
    largest = 0.0
    for n in prange(positions.shape[0]):
        ex, ey, ez = node_slot_sum(n, flat, single_slots, node_offsets, node_slots)
        _, moved = update_node(n, ex, ey, ez, 0.0, 0.0, 0.0, positions, velocities, masses,
                               external_forces, contact_forces, gravity, mass_damping,
                               constrained, prescribed_velocities, first_loaded, first_held,
                               time_step, listed_positions)
        largest = max(largest, moved)
    return largest


central_difference_update = parallel_kernel(_central_difference_update)
central_difference_update_serial = leaf_kernel(
    _serial_twin(_central_difference_update, "central_difference_update_serial"))


def _jointed_update(positions, velocities, element_forces, node_offsets, node_slots, single_slots,
                    masses, external_forces, contact_forces, gravity, mass_damping, constrained,
                    prescribed_velocities, first_loaded, first_held, time_step, joint_forces,
                    joint_slot_rows, listed_positions):
    """:func:`central_difference_update` with the joints' forces added (``joint_forces``: a row
    per joint vertex, ``kernels/joints.joint_forces``; ``joint_slot_rows``: the rows of each
    element slot's three faces); returns also the joints' work over the step. (A loop of its
    own: the bodies without joints read no joint rows.) ``jointed_update_serial``: the same on
    one thread, without reference counts, as ``central_difference_update_serial``.

    19 arguments: as :func:`central_difference_update`, with the joints' force rows.
    """
    flat = element_forces.reshape((-1, 3))
    work = 0.0
    largest = 0.0
    for n in prange(positions.shape[0]):
        ex, ey, ez, jx, jy, jz = joint_slot_sum(n, flat, joint_forces, joint_slot_rows,
                                                single_slots, node_offsets, node_slots)
        node_work, moved = update_node(n, ex, ey, ez, jx, jy, jz, positions, velocities, masses,
                                       external_forces, contact_forces, gravity, mass_damping,
                                       constrained, prescribed_velocities, first_loaded,
                                       first_held, time_step, listed_positions)
        work += node_work
        largest = max(largest, moved)
    return work, largest


jointed_update = parallel_kernel(_jointed_update)
jointed_update_serial = leaf_kernel(_serial_twin(_jointed_update, "jointed_update_serial"))


@parallel_kernel
def cauchy_stresses(positions, velocities, elements, gradients, weights, materials,
                    element_material, stresses):
    """Volume-weighted mean Cauchy stress of every element over its integration points into
    ``stresses`` (n, 3, 3)."""
    n_points = gradients.shape[1]
    n_nodes = elements.shape[1]
    for e in prange(elements.shape[0]):
        material = materials[element_material[e]]
        n0 = elements[e, 0]
        s00 = s11 = s22 = s01 = s12 = s20 = 0.0
        volume = 0.0
        for g in range(n_points):
            f = np.zeros((3, 3))
            fd = np.zeros((3, 3))
            for a in range(1, n_nodes):
                n = elements[e, a]
                for i in range(3):
                    dx = positions[n, i] - positions[n0, i]
                    dv = velocities[n, i] - velocities[n0, i]
                    for j in range(3):
                        f[i, j] += dx * gradients[e, g, a, j]
                        fd[i, j] += dv * gradients[e, g, a, j]
            result = kirchhoff_stress(
                int(material[0]), material[1], material[2], material[3], material[4],
                f[0, 0], f[0, 1], f[0, 2], f[1, 0], f[1, 1], f[1, 2], f[2, 0], f[2, 1], f[2, 2],
                fd[0, 0], fd[0, 1], fd[0, 2], fd[1, 0], fd[1, 1], fd[1, 2], fd[2, 0], fd[2, 1],
                fd[2, 2])
            jac = result[0]
            # sigma = tau / J, weighted by the deformed volume J w
            w = weights[e, g]
            s00 += w * result[1]
            s11 += w * result[2]
            s22 += w * result[3]
            s01 += w * result[4]
            s12 += w * result[5]
            s20 += w * result[6]
            volume += w * jac
        stresses[e, 0, 0] = s00 / volume
        stresses[e, 1, 1] = s11 / volume
        stresses[e, 2, 2] = s22 / volume
        stresses[e, 0, 1] = stresses[e, 1, 0] = s01 / volume
        stresses[e, 1, 2] = stresses[e, 2, 1] = s12 / volume
        stresses[e, 2, 0] = stresses[e, 0, 2] = s20 / volume


@parallel_kernel
def stored_energies(positions, elements, gradients, weights, materials, element_material,
                    energies):
    """Stored elastic energy of every element (J) for the hyperelastic models (1 and 2; NaN for
    the seed's eq. 10, which has none)."""
    n_points = gradients.shape[1]
    n_nodes = elements.shape[1]
    for e in prange(elements.shape[0]):
        material = materials[element_material[e]]
        model = int(material[0])
        mu = material[1]
        lam = material[2]
        kappa = material[3]
        n0 = elements[e, 0]
        energy = 0.0
        for g in range(n_points):
            f = np.zeros((3, 3))
            for a in range(1, n_nodes):
                n = elements[e, a]
                for i in range(3):
                    dx = positions[n, i] - positions[n0, i]
                    for j in range(3):
                        f[i, j] += dx * gradients[e, g, a, j]
            jac = np.linalg.det(f)
            first_invariant = np.sum(f * f)
            if model == 1:
                log_j = math.log(jac)
                density = 0.5 * mu * (first_invariant - 3.0) - mu * log_j + 0.5 * lam * log_j * log_j
            elif model == 2:
                density = (0.5 * mu * (first_invariant / np.cbrt(jac * jac) - 3.0)
                           + 0.25 * kappa * (jac * jac - 1.0 - 2.0 * math.log(jac)))
            else:
                density = np.nan
            energy += weights[e, g] * density
        energies[e] = energy


@kernel
def smallest_jacobian(jacobians):
    """(index, value) of the smallest J."""
    worst = 0
    value = np.inf
    for e in range(jacobians.shape[0]):
        if jacobians[e] < value:
            value = jacobians[e]
            worst = e
    return worst, value


#: Status codes of :func:`advance_steps`.
DONE = 0
INVERTED = 1
REBUILD_CONTACTS = 2
#: Contact pairs are evaluated in parallel from this many on (below, threads cost more than
#: they give: a pair takes about 0.2 microseconds).
PARALLEL_PAIRS = 2000


@kernel
def advance_steps(n_steps, parallel, nodes, element_state, gravity, mass_damping, time_step,
                  contact, joint_data):
    """Up to ``n_steps`` central-difference steps of ``time_step`` without returning to Python.

    ``nodes``: :class:`~riprap.deformable.kernels.bundles.NodeState` (advanced in place);
    ``element_state``: ``ElementState``; ``gravity`` (3,) m/s^2 and ``mass_damping`` (1/s) act
    on every node. ``contact``: ``ContactState`` (no contact: no triangles). ``joint_data``: the
    joints between tets of fracturing bodies, ``JointData`` (no joints: none, and a buffer of no
    rows). Their forces are added in the node update (not to ``contact_forces``), which also sums
    their work. Runs on threads where ``parallel``.
    Returns (steps done, status, element, J): status DONE; INVERTED before the update of a step in
    which ``element`` has J <= 0 (or a non-finite J); REBUILD_CONTACTS before a step once a node has
    moved half the skin since the pairs were listed."""
    (positions, velocities, masses, external_forces, contact_forces, constrained,
     prescribed_velocities, node_offsets, node_slots) = nodes
    (elements, tet4_gradients, gradients, weights, materials, element_material, element_forces,
     jacobians) = element_state
    (wall_triangles, wall_tets, triangles, contact_tets, wall_depths, pairs, penalty, walls,
     listed_positions, skin, totals, triangle_friction, tet_friction, tangential_ratio,
     tet_stiffness, pair_springs, wall_triangle_springs, wall_tet_springs, triangle_damping,
     tet_damping) = contact
    laws = SurfaceLaws(penalty, tangential_ratio, triangle_friction, tet_friction,
                       triangle_damping, tet_damping, tet_stiffness)
    (joint_nodes, joint_sizes, joint_properties, joint_material, joint_damage, joint_broken,
     joint_buffer, joint_slot_rows, joint_released, joint_work, joint_anchors) = joint_data
    has_joints = joint_nodes.shape[0] > 0
    # the nodes before the first loaded one and before the first held one read the first row
    # (zero, free) of the loads and of the held components instead of their own
    # (``update_node``): a body split by joints then reads a fifth fewer bytes per node (the
    # rigid bodies' nodes, held, come after the deformable ones)
    first_loaded = first_held = positions.shape[0]
    for n in range(positions.shape[0] - 1, -1, -1):
        for d in range(3):
            if external_forces[n, d] != 0.0:
                first_loaded = n
            if constrained[n, d]:
                first_held = n
    # nodes at one (element, corner) slot only (all of a body split by joints everywhere) read
    # it straight away, not through the node's list: examples/11's split unit, its node update
    # alone 67 -> 56 microseconds
    single_slots = single_slots_of(node_offsets, node_slots)
    # the one-thread joints' scratch (``joint_forces``; on threads, each block has its own)
    joint_scratch = np.empty(joint_kernels.JOINT_SCRATCH_SIZE if has_joints else 0)
    tet4 = elements.shape[1] == 4
    has_contact = triangles.shape[0] > 0
    half_skin_squared = 0.25 * skin * skin
    # the largest squared move since the pairs were listed: looked at over all nodes once here
    # (rigid nodes are placed between calls), then given by each step's node update
    largest_move = 0.0
    moves_from = listed_positions if has_contact else positions
    if has_contact:
        for n in range(positions.shape[0]):
            moved = 0.0
            for i in range(3):
                moved += (positions[n, i] - listed_positions[n, i]) ** 2
            largest_move = max(largest_move, moved)
    for step in range(n_steps):
        if has_contact:
            if largest_move > half_skin_squared:
                return step, REBUILD_CONTACTS, -1, 1.0
            contact_forces[:] = 0.0
            totals[:] = 0.0
            if pairs.shape[0] >= PARALLEL_PAIRS:
                weight, _ = contact_kernels.pair_forces_parallel(
                    positions, triangles, contact_tets, pairs, contact_forces, velocities, masses,
                    laws, time_step, pair_springs)
            else:
                weight, _ = contact_kernels.pair_forces(
                    positions, triangles, contact_tets, pairs, contact_forces, velocities, masses,
                    laws, time_step, pair_springs)
            totals[walls.shape[0]] = weight
            for w in range(walls.shape[0]):
                force, _ = contact_kernels.wall_forces(positions, wall_triangles, wall_tets,
                                                       walls[w], wall_depths, contact_forces,
                                                       velocities, masses, laws, time_step,
                                                       wall_triangle_springs[w],
                                                       wall_tet_springs[w])
                totals[w] = force
        if has_joints and parallel:
            # (joints exist only between 4-node tets); their forces join the node update, which
            # also sums their work
            tet4_and_joint_forces(positions, velocities, elements, tet4_gradients, weights[:, 0],
                                  materials, element_material, element_forces, jacobians,
                                  joint_data)
        elif not parallel:
            if has_joints:
                joint_kernels.joint_forces(
                    positions, joint_nodes, joint_sizes, joint_properties, joint_material,
                    joint_damage, joint_broken, joint_released, joint_anchors, joint_buffer,
                    joint_scratch)
            element_forces_serial(positions, velocities, elements, tet4_gradients, gradients,
                                  weights, materials, element_material, element_forces, jacobians)
        elif tet4:
            tet4_element_forces(positions, velocities, elements, tet4_gradients, weights[:, 0],
                                materials, element_material, element_forces, jacobians)
        else:
            general_element_forces(positions, velocities, elements, gradients, weights, materials,
                                   element_material, element_forces, jacobians)
        worst, value = smallest_jacobian(jacobians)
        if not value > 0.0:
            return step, INVERTED, worst, value
        if has_joints and parallel:
            work, largest_move = jointed_update(
                positions, velocities, element_forces, node_offsets, node_slots, single_slots,
                masses, external_forces, contact_forces, gravity, mass_damping, constrained,
                prescribed_velocities, first_loaded, first_held, time_step, joint_buffer,
                joint_slot_rows, moves_from)
            joint_work[0] += work
        elif has_joints:
            work, largest_move = jointed_update_serial(
                positions, velocities, element_forces, node_offsets, node_slots, single_slots,
                masses, external_forces, contact_forces, gravity, mass_damping, constrained,
                prescribed_velocities, first_loaded, first_held, time_step, joint_buffer,
                joint_slot_rows, moves_from)
            joint_work[0] += work
        elif parallel:
            largest_move = central_difference_update(
                positions, velocities, element_forces, node_offsets, node_slots, single_slots,
                masses, external_forces, contact_forces, gravity, mass_damping, constrained,
                prescribed_velocities, first_loaded, first_held, time_step, moves_from)
        else:
            largest_move = central_difference_update_serial(
                positions, velocities, element_forces, node_offsets, node_slots, single_slots,
                masses, external_forces, contact_forces, gravity, mass_damping, constrained,
                prescribed_velocities, first_loaded, first_held, time_step, moves_from)
    return n_steps, DONE, -1, 1.0
