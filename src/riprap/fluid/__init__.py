"""Two-phase (air and water) incompressible flow on a staggered Cartesian grid with a sharp interface."""
