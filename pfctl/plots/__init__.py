"""Every figure: follow, search, prediction, map and behavior-tree drawings (DESIGN.md)."""
