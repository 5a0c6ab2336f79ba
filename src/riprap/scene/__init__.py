"""What a run holds before it runs (:class:`Scene`), and which model runs it
(:mod:`riprap.scene.choose_model`)."""
from riprap.scene.scene import DEFAULT_GRAVITY, Scene

__all__ = ["DEFAULT_GRAVITY", "Scene"]
