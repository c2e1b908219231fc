"""The behavior tree (§II-A): leaves, the tree built from the mission layout, drawings."""
