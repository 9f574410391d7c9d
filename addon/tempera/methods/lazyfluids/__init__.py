"""LazyFluids (Jamriška et al. 2015): fluid elements with uniform patch usage."""
