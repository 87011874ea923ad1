"""Run time, start-up, memory, scaling and throughput; the GPU check."""
