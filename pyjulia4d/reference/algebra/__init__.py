"""float64 twins of kernels/algebra/*.cl, file for file."""
