"""Other programs' scenes: POV-Ray's julia_fractal."""
