"""The jobs and tools around the engine (native/src/app): the guide cache, frame ranges, settings, the command
lines, the farm, media sources and contact sheets."""
