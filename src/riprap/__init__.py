"""riprap: numerical breakwater modelling with rigid and deformable FEMDEM bodies."""
__version__ = "0.1.0"
