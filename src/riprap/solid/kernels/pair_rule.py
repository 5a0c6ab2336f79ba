"""How two materials in contact combine: the one home of the pair rule, read by the rigid
contact tables (``solid/materials.py`` ``pair_tables``), the deformable contact kernels and the
analysis of a layer's contacts.

A pair takes the smaller friction coefficient, the smaller restitution and the smaller contact
penalty of its two materials (the penalty as in Y3D): the weaker material governs. A case's
``[[friction]]`` table gives named pairs their own friction coefficient instead
(``solid/materials.py`` ``friction_table``, which the rigid pair tables and the layer analysis
read; the deformable contact takes this rule and refuses pairs naming its materials). Each rule is
written with ``np.minimum`` so that the same function serves compiled kernels (inlined, on
scalars) and Python (``.py_func``, on scalars or arrays of materials).
"""
import numpy as np

from riprap._jit import inline_kernel

#: The rule in words, for logs and messages.
PAIR_RULE_TEXT = ("contact pairs combine materials by the smaller friction coefficient (unless "
                  "[[friction]] gives the pair's), the smaller restitution and the smaller "
                  "contact_penalty")


@inline_kernel
def pair_friction(friction_a, friction_b):
    """Coulomb friction coefficient of a contact between two materials."""
    return np.minimum(friction_a, friction_b)


@inline_kernel
def pair_restitution(restitution_a, restitution_b):
    """Normal coefficient of restitution of a contact between two materials."""
    return np.minimum(restitution_a, restitution_b)


@inline_kernel
def pair_penalty(penalty_a, penalty_b):
    """Contact penalty (Pa) of a contact between two materials."""
    return np.minimum(penalty_a, penalty_b)
