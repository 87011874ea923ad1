"""Error against a float64 brute force, and against run time."""
