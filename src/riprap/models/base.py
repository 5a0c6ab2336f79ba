"""The interface between the run loop and a model (rigid bodies, fluid, both coupled; deformable
bodies next)."""
from __future__ import annotations

from riprap.errors import RiprapError

__all__ = ["Model"]


class Model:
    """Base of every model the run loop drives. Subclasses fill in the methods that raise.

    The loop calls, in this order: :meth:`prepare` once; it opens the writers
    (:meth:`default_writers` and the user's, :mod:`riprap.outputs`); then repeatedly
    :meth:`advance` towards the next scheduled time, :meth:`state_arrays` after each good chunk,
    and the writers whose schedule :meth:`reached` says has come; and at the end it closes the
    writers and asks for :meth:`summary_fields`.
    """

    #: Checkpoint kind: a checkpoint is restarted only by a model of the same kind.
    kind = "riprap model"
    #: What summary.json calls this model ("rigid", "fluid", "coupled").
    name = "model"

    # ------------------------------------------------------------------ clock
    @property
    def time(self) -> float:
        raise NotImplementedError

    @property
    def step_count(self) -> int:
        raise NotImplementedError

    def reached(self, time: float) -> bool:
        """Whether the model's clock has reached ``time`` (within its own rounding)."""
        raise NotImplementedError

    def prepare(self, *, restarted: bool) -> None:
        """Choose time steps and check the start state (not the overlaps of a restart)."""

    def advance(self, until: float) -> None:
        """Advance by a chunk of work that ends at ``until`` or before it (one fluid step, or as
        many contact steps as fit a fraction of a second of wall time). Raises
        :class:`riprap.errors.InstabilityError` naming what failed, where and when."""
        raise NotImplementedError

    def recover(self, good: dict) -> bool:
        """After a failed chunk: return True to retry from ``good`` (e.g. with a smaller step);
        False stops the run with a failure checkpoint."""
        return False

    def after_good_chunk(self) -> None:
        """Called after every chunk that did not fail (e.g. to grow an adaptive step)."""

    def state_changed(self) -> None:
        """Called where the state was changed from outside the model (a run's ``after_chunk``
        callback fixed or moved bodies): what the model watched from before is void."""

    def at_rest(self) -> bool:
        """Whether the run may stop early because everything rests."""
        return False

    def last_time_step(self) -> float:
        raise NotImplementedError

    # ------------------------------------------------------------------ state
    def state_arrays(self) -> dict:
        raise NotImplementedError

    def load_state_arrays(self, arrays: dict) -> None:
        raise NotImplementedError

    def start_bodies_at_rest_from(self, arrays: dict) -> None:
        """Start from the bodies' end state of another run of the same bodies (``bodies_*``
        arrays of its checkpoint), at rest: a step of a test series."""
        raise RiprapError(f"a {self.name} run cannot start from another run's bodies")

    def checkpoint_content(self, state: dict) -> tuple[dict, dict]:
        """(arrays, metadata) of a checkpoint of ``state``: the state and what a restart checks."""
        return dict(state), {}

    def check_checkpoint(self, path, arrays: dict, metadata: dict) -> None:
        """Refuse a checkpoint written for another case (raise RiprapError naming ``path``)."""

    @property
    def writes_files(self) -> bool:
        """Whether this process writes the run's files (of a run over several processes, only
        process 0 does)."""
        return True

    def prepare_outputs(self) -> None:
        """Make the data the writers ask for current (a run over several processes gathers its
        slabs here; every process calls it when outputs are due)."""

    def restore(self, arrays: dict) -> None:
        """Take the state of a checkpoint being restarted from."""
        self.load_state_arrays(arrays)

    # ------------------------------------------------------------------ outputs
    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        """The writers of this model's outputs (:mod:`riprap.outputs`; ``[output]`` paraview and
        picture), with no schedule of their own (the run gives each its interval). The model
        gives them data (its solver, data methods); it writes no file itself."""
        return []

    def progress_text(self) -> str:
        """One line of the model's figures for the progress bar."""
        return ""

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        """The model's figures for ``summary.json``."""
        return {}

    def failure_advice(self, good: dict) -> str:
        """What to change after a blow-up, judged from the last good state."""
        return ""
