"""float64 twins of kernels/kind/*.cl, file for file: the sets other than the Julia set of
q -> f(q) + c (mandelbrot.py) and the rotated map (rotate.py)."""
