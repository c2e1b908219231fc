"""The algorithms of pfctl. Imports numpy/scipy/shapely/networkx and itself only (DESIGN.md)."""
