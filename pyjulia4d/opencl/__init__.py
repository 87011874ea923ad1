"""The OpenCL executor: runtimes and devices, program builds, packet widths, running a plan."""
