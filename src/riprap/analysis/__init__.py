"""Analysis of armour layers: what each unit carries, touches and how it lies (the seed paper's
post-processing: contact forces, coordination numbers, stereonets, factors of safety).

Reading a pack or a run and writing the report is the workflow above it: ``riprap.analyse`` and
``riprap.compare_layers`` (:mod:`riprap.workflows.analyse`)."""
from riprap.analysis.layer_analysis import LayerAnalysis, analyse_layer
from riprap.analysis.layer_state import LayerDescription, LayerState, state_from_simulation
from riprap.analysis.rocking import rocking_factor_of_safety
from riprap.solid.contact_statistics import UnitContacts, sliding_factor_of_safety, unit_contacts

__all__ = ["LayerAnalysis", "LayerDescription", "LayerState", "UnitContacts",
           "analyse_layer", "rocking_factor_of_safety",
           "sliding_factor_of_safety", "state_from_simulation", "unit_contacts"]
