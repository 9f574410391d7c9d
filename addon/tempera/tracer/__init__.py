"""The light-path-expression tracer (native/src/tracer) and the scene units it takes from Blender."""
