"""One package per paper, beside its native folder (native/src/methods/<method>): each method of the
registry (tempera.methods.registry) and the noise pass."""
