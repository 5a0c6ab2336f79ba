"""Named errors. Every message says what is wrong, where (file, line, key, body) and what to do."""


class RiprapError(Exception):
    """Base class of every error riprap raises on purpose."""


class CaseFileError(RiprapError):
    """A case file (TOML) or API argument has a wrong key, type or value."""

    @classmethod
    def from_problems(cls, messages, limit: int) -> "CaseFileError":
        """One error listing up to ``limit`` messages (already sorted), then a count of the rest;
        the full list stays in ``.problems``."""
        messages = list(messages)
        shown = messages[:limit]
        hidden = len(messages) - len(shown)
        if hidden:
            shown.append(f"... and {hidden} more problem(s) not shown; fix the ones above first")
        error = cls("\n".join(shown))
        error.problems = tuple(messages)
        return error


class MeshError(RiprapError):
    """A mesh is open, inverted, self-intersecting, degenerate or could not be read."""


class OverlapError(RiprapError):
    """Bodies overlap where they must not (at the start of a run, or at placement)."""


class InstabilityError(RiprapError):
    """The state became non-finite or the time step is unstable; a checkpoint was written."""


class KernelOverflowError(RiprapError):
    """A fixed-capacity buffer in a compiled kernel was too small."""
