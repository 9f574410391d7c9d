"""The synthesis engine on numpy arrays (native/src/engine): guided patch-based synthesis, guides, motion and colour."""
