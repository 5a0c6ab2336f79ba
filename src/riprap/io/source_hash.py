"""A hash of riprap's own compiled-kernel sources, which stamps numba's on-disk cache
(:mod:`riprap._jit`)."""
from __future__ import annotations

import hashlib
import os

__all__ = ["kernel_source_hash"]


def kernel_source_hash(package_dir: str, extra_files=(), salt: str = "") -> str:
    """SHA-256 of every ``.py`` file in a ``kernels`` folder under ``package_dir``, of
    ``extra_files`` and of ``salt``, in a fixed order."""
    digest = hashlib.sha256(salt.encode())
    paths = []
    for root, folders, files in os.walk(package_dir):
        folders.sort()
        if os.path.basename(root) == "kernels":
            paths += [os.path.join(root, name) for name in sorted(files) if name.endswith(".py")]
    for path in sorted(paths) + [os.path.abspath(p) for p in extra_files]:
        with open(path, "rb") as stream:
            digest.update(os.path.relpath(path, package_dir).encode() + b"\0" + stream.read())
    return digest.hexdigest()
