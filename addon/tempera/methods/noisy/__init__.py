"""Color Me Noisy (Fišer et al. 2014): a controllable amount of temporal noise."""
