"""StyLit (Fišer et al. 2016): stylization guided by light-path expressions, its painting template and exemplar kit."""
