"""Analysis of packs and runs: what each unit carries and touches (issue 4, in progress)."""
from riprap.analysis.unit_contacts import UnitContacts, unit_contacts

__all__ = ["UnitContacts", "unit_contacts"]
