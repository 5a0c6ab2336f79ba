"""Compiled kernels of the placement tools (flat arrays in, flat arrays out)."""
