"""Limits that several rooms apply: each written once, here, on the lowest floor (it imports
nothing), so that the rigid run, the coupled run, the deformable run and placement cannot drift
apart."""

__all__ = ["PROGRESS_PERIOD", "RUNAWAY_SPEED", "START_OVERLAP_FRACTION"]

#: A body faster than this (m/s) has blown up, even while its numbers are still finite: no armour
#: unit or rock moves so fast.
RUNAWAY_SPEED = 1.0e3

#: Bodies may touch but not overlap at the start: a mean overlap depth above this fraction of the
#: smallest boundary sub-tet height is refused (a just-touching placement gives exactly zero).
START_OVERLAP_FRACTION = 0.01

#: Wall-clock seconds a model's chunk of work aims at: the run loop updates the progress bar and
#: checks for rest between chunks.
PROGRESS_PERIOD = 0.25
