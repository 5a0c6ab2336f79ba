"""Analysis of armour layers: what each unit carries, touches and how it lies (the seed paper's
post-processing: contact forces, coordination numbers, stereonets, factors of safety)."""
from riprap.analysis.api import analyse, compare_layers
from riprap.analysis.layer_analysis import LayerAnalysis, analyse_layer
from riprap.analysis.layer_state import LayerDescription, LayerState, state_from_simulation
from riprap.analysis.rocking import rocking_factor_of_safety
from riprap.analysis.unit_contacts import UnitContacts, sliding_factor_of_safety, unit_contacts

__all__ = ["LayerAnalysis", "LayerDescription", "LayerState", "UnitContacts", "analyse",
           "analyse_layer", "compare_layers", "rocking_factor_of_safety",
           "sliding_factor_of_safety", "state_from_simulation", "unit_contacts"]
