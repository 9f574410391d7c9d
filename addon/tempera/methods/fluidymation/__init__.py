"""Fluidymation (Platkevič et al. 2021): moving shapes painted with a video exemplar of a natural medium."""
