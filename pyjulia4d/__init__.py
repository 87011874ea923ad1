"""pyjulia4d: OpenCL ray tracing of 3D views of 4D quaternion Julia sets.

    >>> from pyjulia4d import Scene, render
    >>> result = render(Scene.default().with_overrides(["image.width=320"]))

``render`` runs the OpenCL kernels; ``pyjulia4d.reference.render`` is the float64
numpy twin (slow, for small images).
"""
from . import runtimes

runtimes.register()  # before any OpenCL call: Intel's CPU runtime from PyPI (runtimes.py)

from .scene import Scene, SceneError  # noqa: E402
from .render import RenderResult, render  # noqa: E402  (the function shadows the module name on purpose)

__version__ = "0.1.0"
__all__ = ["Scene", "SceneError", "RenderResult", "render", "__version__"]
