"""Benchmark cases with published reference data, shared by bench/, tests/verification/ and examples/."""
