"""One package per paper (native/src/methods/<method>): stylit, tcia, noisy, lazyfluids, fluidymation, rigid."""
