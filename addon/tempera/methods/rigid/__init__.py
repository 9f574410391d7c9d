"""Example-based expressive animation of 2D rigid bodies (Dvorožňák et al. 2017)."""
