"""float64 twins of kernels/enclose/: orbit enclosures for the proven march (march/proven.cl)."""
