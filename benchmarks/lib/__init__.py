"""What the benchmark scripts share: their command lines and their results files."""
