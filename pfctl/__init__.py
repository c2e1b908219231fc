"""pfctl: person-following with active target search (Kim et al., UT Austin / Toyota HSR)."""

__version__ = "0.1.0"
