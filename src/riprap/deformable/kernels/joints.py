"""Compiled kernel of the joint (cohesive) elements between the tets of an exploded mesh: Munjiza's
combined single and smeared crack model (Munjiza, Andrews & White 1999, Int. J. Numer. Meth.
Engng 44: 41; the form of Y3D's 6-node joint).

A joint holds face A of one tet to the matching face B of its neighbour: nodes ``joints[j, 0:3]``
(A) and ``joints[j, 3:6]`` (B, node k paired with A's node k), ordered so that the mid-surface
normal points from A to B. At three points (the mid-surface's mid-edges) the separation
delta = x_B - x_A gives the opening o = delta . n and the slip vector s = delta - o n; their
stresses (tension and shear positive) pull A towards B with the traction sigma n + tau s / |s|
over a third of the mid-surface's area each, shared by the point's two vertices.

Per point, with f_t the tensile strength, f_s = c - tan(phi) min(sigma, 0) the shear strength,
o_p = 2 h f_t / p and s_p = 2 h f_s / p the openings at the strengths (h the joint's size, p the
joint penalty), o_t, s_t the softening lengths:

    damage  D = max(D_before, sqrt(max(o - o_p, 0)^2 / o_t^2 + max(|s| - s_p, 0)^2 / s_t^2)), <= 1
    sigma   = 2 (o / o_p) f_t in compression (o < 0, undamaged: the faces may not interpenetrate)
            = (2 r - r^2) z(D) f_t,  r = o / o_p,  for 0 <= o < o_p
            = z(D) f_t                             for o >= o_p
    tau     likewise with |s|, s_p, f_s
    z(D)    = [1 - (a + b - 1)/(a + b) exp(D (a + c b)/((a + b)(1 - a - b)))] [a (1 - D) + b (1 - D)^c]

with a = 0.63, b = 1.8, c = 6 (Hordijk's curve). A joint whose points reach D = 1 at two of the
three breaks: it then carries only the compressive penalty (its faces cannot pass through each
other) and no tension or shear.
"""
import math

import numpy as np

from riprap._jit import inline_kernel, kernel, parallel_kernel, prange

SOFTENING_A = 0.63
SOFTENING_B = 1.8
SOFTENING_C = 6.0


@inline_kernel
def softening(damage):
    """z(D) of the module docstring: 1 at D = 0, 0 at D = 1."""
    if damage >= 1.0:
        return 0.0
    if damage <= 0.0:
        return 1.0
    a, b, c = SOFTENING_A, SOFTENING_B, SOFTENING_C
    first = 1.0 - (a + b - 1.0) / (a + b) * math.exp(damage * (a + c * b) / ((a + b) * (1.0 - a - b)))
    rest = 1.0 - damage
    return first * (a * rest + b * rest ** c)


@inline_kernel
def _rising(ratio):
    """2 r - r^2, the curve up to the strength (slope 2 at 0, 0 at the peak)."""
    return (2.0 - ratio) * ratio


@kernel
def _joint(j, positions, joints, sizes, properties, damage, broken, forces_a, forces_b):
    """Forces on the six nodes of joint ``j`` into forces_a/forces_b (3, 3); updates its damage.
    Returns the number of its points at D >= 1."""
    tensile, cohesion, tan_phi, penalty, softening_i, softening_ii = (
        properties[0], properties[1], properties[2], properties[3], properties[4], properties[5])
    h = sizes[j]
    delta = np.empty((3, 3))
    middle = np.empty((3, 3))
    for k in range(3):
        for d in range(3):
            xa = positions[joints[j, k], d]
            xb = positions[joints[j, 3 + k], d]
            delta[k, d] = xb - xa
            middle[k, d] = 0.5 * (xa + xb)
    e1 = middle[1] - middle[0]
    e2 = middle[2] - middle[0]
    normal = np.array([e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]])
    twice_area = math.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
    for k in range(3):
        for d in range(3):
            forces_a[k, d] = 0.0
            forces_b[k, d] = 0.0
    if twice_area <= 0.0:
        return 0
    normal /= twice_area
    weight = twice_area / 6.0                          # a third of the area per point
    opening_peak = 2.0 * h * tensile / penalty
    failed = 0
    for q in range(3):
        k0 = q
        k1 = (q + 1) % 3
        d_vec = 0.5 * (delta[k0] + delta[k1])
        opening = d_vec[0] * normal[0] + d_vec[1] * normal[1] + d_vec[2] * normal[2]
        slip_vec = d_vec - opening * normal
        slip = math.sqrt(slip_vec[0] ** 2 + slip_vec[1] ** 2 + slip_vec[2] ** 2)
        if broken[j]:
            sigma = 2.0 * opening / opening_peak * tensile if opening < 0.0 else 0.0
            tau = 0.0
        else:
            # strengths and softening lengths of this point
            sigma_trial = 2.0 * opening / opening_peak * tensile if opening < 0.0 else 0.0
            shear_strength = cohesion - tan_phi * sigma_trial
            slip_peak = 2.0 * h * shear_strength / penalty
            opening_soft = softening_i / tensile
            slip_soft = softening_ii / shear_strength
            excess_o = max(opening - opening_peak, 0.0) / opening_soft
            excess_s = max(slip - slip_peak, 0.0) / slip_soft
            now = math.sqrt(excess_o * excess_o + excess_s * excess_s)
            current = max(damage[j, q], min(now, 1.0))
            damage[j, q] = current
            z = softening(current)
            if opening < 0.0:
                sigma = sigma_trial
            elif opening < opening_peak:
                sigma = _rising(opening / opening_peak) * z * tensile
            else:
                sigma = z * tensile
            if slip < slip_peak:
                tau = _rising(slip / slip_peak) * z * shear_strength
            else:
                tau = z * shear_strength
            if current >= 1.0:
                failed += 1
        traction = sigma * normal
        if slip > 0.0 and tau != 0.0:
            traction = traction + (tau / slip) * slip_vec
        for d in range(3):
            share = 0.5 * weight * traction[d]
            forces_a[k0, d] += share
            forces_a[k1, d] += share
            forces_b[k0, d] -= share
            forces_b[k1, d] -= share
    return failed


@parallel_kernel
def joint_forces(positions, joints, sizes, properties, damage, broken, joint_force_buffer):
    """Forces of every joint (``_joint``) into ``joint_force_buffer`` (n_joints, 6, 3); a joint
    with two or more points at D >= 1 is marked ``broken``. Returns the number broken now."""
    n = joints.shape[0]
    newly = np.zeros(n, dtype=np.int64)
    for j in prange(n):
        forces_a = np.empty((3, 3))
        forces_b = np.empty((3, 3))
        failed = _joint(j, positions, joints, sizes, properties, damage, broken, forces_a, forces_b)
        for k in range(3):
            for d in range(3):
                joint_force_buffer[j, k, d] = forces_a[k, d]
                joint_force_buffer[j, 3 + k, d] = forces_b[k, d]
        if not broken[j] and failed >= 2:
            broken[j] = True
            newly[j] = 1
    return newly.sum()


@kernel
def gather_joint_forces(joint_force_buffer, node_offsets, node_slots, out):
    """out[node] += the joint forces on it: ``node_slots[node_offsets[i]:node_offsets[i+1]]``
    are the flat (joint * 6 + corner) slots of node i."""
    flat = joint_force_buffer.reshape(-1, 3)
    for node in range(out.shape[0]):
        for s in range(node_offsets[node], node_offsets[node + 1]):
            slot = node_slots[s]
            for d in range(3):
                out[node, d] += flat[slot, d]
