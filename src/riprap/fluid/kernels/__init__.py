"""Compiled (numba) kernels of the fluid solver."""
