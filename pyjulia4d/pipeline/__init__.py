"""From a scene to the kernels' arguments and back: the plan and its tiles, the kernel
configuration, the work bound and time prediction, framing, antialiasing, the result.
No OpenCL here: both executors (opencl/, reference/) take what this package resolves."""
