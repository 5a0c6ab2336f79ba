"""Named errors. Every message says what is wrong, where (file, line, key, body) and what to do."""


class RiprapError(Exception):
    """Base class of every error riprap raises on purpose."""


class CaseFileError(RiprapError):
    """A case file (TOML) or API argument has a wrong key, type or value."""


class MeshError(RiprapError):
    """A mesh is open, inverted, self-intersecting, degenerate or could not be read."""


class OverlapError(RiprapError):
    """Bodies overlap where they must not (at the start of a run, or at placement)."""


class InstabilityError(RiprapError):
    """The state became non-finite or the time step is unstable; a checkpoint was written."""


class KernelOverflowError(RiprapError):
    """A fixed-capacity buffer in a compiled kernel was too small."""
