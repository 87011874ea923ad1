"""pyjulia4d: OpenCL ray tracing of 3D views of 4D quaternion Julia sets."""

__version__ = "0.1.0"
