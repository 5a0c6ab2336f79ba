"""Solids in the fluid grid: the exact volume of each body in each fluid cell (the paper's
supermesh on riprap's Cartesian grid), the groundwork of two-way coupling."""
