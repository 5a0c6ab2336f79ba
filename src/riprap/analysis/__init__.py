"""Analysis of packs and runs: what each unit carries and touches (issue 4, in progress)."""
from riprap.analysis.unit_contacts import UnitContacts, sliding_factor_of_safety, unit_contacts

__all__ = ["UnitContacts", "sliding_factor_of_safety", "unit_contacts"]
