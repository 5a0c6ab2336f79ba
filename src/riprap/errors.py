"""Named errors. Every message says what is wrong, where (file, line, key, body) and what to do."""


import re

# numpy's reprs of scalars and small arrays, as an f-string's {value!r} or a tuple of numpy values
# writes them (np.float64(0.28), np.True_, array([0., 1.])): shown as the user typed the numbers.
_NUMPY_SCALAR = re.compile(r"np\.(?:float|int|uint|complex)\d*\(([^()]*)\)")
_NUMPY_BOOL = re.compile(r"np\.(True|False)_")
_NUMPY_STRING = re.compile(r"np\.str_\(('[^']*'|\"[^\"]*\")\)")
_NUMPY_ARRAY = re.compile(r"array\((\[[^()]*\])(?:, dtype=\w+)?\)")


def plain_numbers(text: str) -> str:
    """``text`` with numpy's reprs of numbers replaced by the numbers: np.float64(0.28) -> 0.28."""
    text = _NUMPY_SCALAR.sub(r"\1", text)
    text = _NUMPY_BOOL.sub(r"\1", text)
    text = _NUMPY_STRING.sub(r"\1", text)
    return _NUMPY_ARRAY.sub(r"\1", text)


class RiprapError(Exception):
    """Base class of every error riprap raises on purpose. Its text never shows numpy's reprs
    (``np.float64(0.28)``), whichever message formatted a numpy value with ``!r``."""

    def __str__(self) -> str:
        return plain_numbers(super().__str__())


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
