"""Small JSON outputs (run summaries): written by :func:`riprap.io.json_files.write_json`, which
every JSON file of riprap goes through (non-finite numbers as ``null``, standard JSON only)."""
from riprap.io.json_files import write_json

__all__ = ["write_json"]
