"""Time integration of rigid bodies: velocity Verlet (kick-drift-kick) for translation and the
symplectic splitting of Dullweber, Leimkuhler & McLachlan (1997, J. Chem. Phys. 107, 5840) for
rotation.

Translation: exact for constant force (free fall, projectiles). Rotation: the world angular momentum
L is held unchanged through the drift (torque-free motion conserves it exactly), and the orientation
is advanced by exact rotations about the principal axes in the sequence 1(dt/2) 2(dt/2) 3(dt)
2(dt/2) 1(dt/2); the scheme is symplectic and time-reversible, so the kinetic energy of a free
rotor stays within a bounded O(dt^2) band instead of drifting.

Numerical damping, named ``local_damping`` (Cundall 1987, as in Yade's NewtonIntegrator): each
force and torque component is reduced by ``local_damping * |component|`` against the sign of the
matching velocity component. It is off (0) by default; placement and demos use it to settle.
"""
import numpy as np

from riprap._jit import kernel
from riprap.solid.kernels.geometry_ops import rotation_matrix


@kernel
def angular_velocities(quaternions, angular_momenta, inverse_principal_inertia):
    """World angular velocity omega = R I^-1 R^T L of every body, (n, 3)."""
    n = quaternions.shape[0]
    out = np.zeros((n, 3))
    for b in range(n):
        r = rotation_matrix(quaternions[b])
        body = np.zeros(3)
        for i in range(3):
            body[i] = (r[0, i] * angular_momenta[b, 0] + r[1, i] * angular_momenta[b, 1]
                       + r[2, i] * angular_momenta[b, 2]) * inverse_principal_inertia[b, i]
        for i in range(3):
            out[b, i] = r[i, 0] * body[0] + r[i, 1] * body[1] + r[i, 2] * body[2]
    return out


@kernel
def kick(velocities, angular_momenta, omegas, forces, torques, inverse_masses, half_step,
         local_damping):
    """Half-step velocity and angular momentum update with optional local damping."""
    n = velocities.shape[0]
    for b in range(n):
        if inverse_masses[b] == 0.0:
            continue
        for c in range(3):
            f = forces[b, c]
            t = torques[b, c]
            if local_damping > 0.0:
                f -= local_damping * abs(f) * np.sign(velocities[b, c])
                t -= local_damping * abs(t) * np.sign(omegas[b, c])
            velocities[b, c] += half_step * f * inverse_masses[b]
            angular_momenta[b, c] += half_step * t


@kernel
def _rotate_about_axis(q, pi, axis, angle):
    """q <- q * (rotation by angle about body axis); pi <- rotated by -angle about that axis."""
    half = 0.5 * angle
    c = np.cos(half)
    s = np.sin(half)
    # quaternion product q * (c, s e_axis)
    w, x, y, z = q[0], q[1], q[2], q[3]
    if axis == 0:
        q[0] = w * c - x * s
        q[1] = x * c + w * s
        q[2] = y * c + z * s
        q[3] = z * c - y * s
    elif axis == 1:
        q[0] = w * c - y * s
        q[1] = x * c - z * s
        q[2] = y * c + w * s
        q[3] = z * c + x * s
    else:
        q[0] = w * c - z * s
        q[1] = x * c + y * s
        q[2] = y * c - x * s
        q[3] = z * c + w * s
    cos = np.cos(angle)
    sin = np.sin(angle)
    i = (axis + 1) % 3
    j = (axis + 2) % 3
    a = pi[i]
    b = pi[j]
    pi[i] = cos * a + sin * b
    pi[j] = -sin * a + cos * b


@kernel
def drift(positions, quaternions, velocities, angular_momenta, inverse_masses,
          inverse_principal_inertia, step):
    """Advance positions and orientations over ``step`` at constant velocity and momentum."""
    n = positions.shape[0]
    pi = np.zeros(3)
    for b in range(n):
        if inverse_masses[b] == 0.0:
            continue
        for c in range(3):
            positions[b, c] += step * velocities[b, c]
        q = quaternions[b]
        r = rotation_matrix(q)
        for i in range(3):
            pi[i] = r[0, i] * angular_momenta[b, 0] + r[1, i] * angular_momenta[b, 1] + r[2, i] * angular_momenta[b, 2]
        if pi[0] == 0.0 and pi[1] == 0.0 and pi[2] == 0.0:
            continue
        inv = inverse_principal_inertia[b]
        _rotate_about_axis(q, pi, 0, 0.5 * step * pi[0] * inv[0])
        _rotate_about_axis(q, pi, 1, 0.5 * step * pi[1] * inv[1])
        _rotate_about_axis(q, pi, 2, step * pi[2] * inv[2])
        _rotate_about_axis(q, pi, 1, 0.5 * step * pi[1] * inv[1])
        _rotate_about_axis(q, pi, 0, 0.5 * step * pi[0] * inv[0])
        norm = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
        for c in range(4):
            q[c] /= norm
