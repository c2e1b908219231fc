"""Trajectory prediction of a lost target (§II-E, §III): the models, clipping to the
map, evaluation on real tracks, hyperparameter search."""
