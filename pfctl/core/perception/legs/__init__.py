"""Leg detection in the 2-D laser (§II-E): segments, features, the random forest,
evidence over scans, training."""
