"""Ground truth and the catalogue of stiff and extreme cases, for tests and benchmarks."""
