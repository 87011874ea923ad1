"""The files pyjulia4d ships: sky.exr, the path tracer's daylight environment (sky.py makes it)."""
