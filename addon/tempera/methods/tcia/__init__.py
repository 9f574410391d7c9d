"""Stylizing Animation by Example (Bénard et al. 2013): coherent sweeps and painted keyframes."""
