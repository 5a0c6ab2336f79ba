"""Compiled (numba) kernels of the solid-fluid coupling."""
