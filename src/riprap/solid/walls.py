"""Walls: fixed half-spaces. A box container is five or six of them."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of


@dataclass(frozen=True)
class Wall:
    """The half-space {x : normal . (x - point) < 0}; ``normal`` points into the free space."""

    point: tuple
    normal: tuple
    material: str

    def __post_init__(self):
        n = np.asarray(self.normal, dtype=float)
        norm = float(np.linalg.norm(n))
        if not np.isfinite(norm) or norm < 1e-12:
            raise CaseFileError(f"wall normal {self.normal!r} must be a non-zero vector")
        object.__setattr__(self, "normal", tuple(float(v) for v in n / norm))
        object.__setattr__(self, "point", tuple(float(v) for v in self.point))


def plane(*, point, normal, material: str) -> list[Wall]:
    return [Wall(point=tuple(point), normal=tuple(normal), material=material)]


def box(*, min, max, material: str,
        open_top: bool = default_of("walls", "open_top")) -> list[Wall]:
    """A container: the inside of the box [min, max] is free space."""
    lo = np.asarray(min, dtype=float)
    hi = np.asarray(max, dtype=float)
    if np.any(hi <= lo):
        raise CaseFileError(f"box walls: max {tuple(hi)} must exceed min {tuple(lo)} in every axis")
    walls = []
    for axis in range(3):
        n = np.zeros(3)
        n[axis] = 1.0
        walls.append(Wall(point=tuple(lo), normal=tuple(n), material=material))
        if axis == 2 and open_top:
            continue
        walls.append(Wall(point=tuple(hi), normal=tuple(-n), material=material))
    return walls
