"""pyjulia4d: OpenCL ray tracing of 3D views of 4D Julia sets.

    >>> from pyjulia4d import Scene, render
    >>> result = render(Scene.default().with_overrides(["image.width=320"]))

``render`` runs the OpenCL kernels (opencl/executor.py); ``pyjulia4d.reference.render`` is
the float64 numpy twin (slow, for small images), which needs no OpenCL.  The package's
folders follow a render's path: scene/ (the scene and its checks) -> pipeline/ (the plan,
tiles, the numbers the kernels take, the result) -> opencl/ or reference/ (two executors of
one plan) -> app/ (the command line, animation, the cluster, files); fractal/ holds the
registry of algebras, functions and kinds, geometry/ the 4D camera, interop/ POV-Ray
import, measure/ ground truth and the catalogue of hard cases.
"""
from pyjulia4d.opencl import runtimes

runtimes.register()  # before any OpenCL call: Intel's CPU runtime from PyPI (opencl/runtimes.py)
runtimes.pyopencl_cache()  # before pyopencl is imported: its caches off where they cannot be made

__version__ = "0.1.0"
__all__ = ["Scene", "SceneError", "RenderResult", "render", "__version__"]


def __getattr__(name: str):
    """The names of ``__all__``, imported on first use: ``render`` brings pyopencl, which the
    scene model, the reference and the command line's error paths do without, and the others
    numpy, which the program imports only once it has set its threads (__main__.py)."""
    if name == "render":
        from pyjulia4d.opencl.executor import render

        return render
    if name == "Scene":
        from pyjulia4d.scene.model import Scene

        return Scene
    if name == "SceneError":
        from pyjulia4d.scene.checks import SceneError

        return SceneError
    if name == "RenderResult":
        from pyjulia4d.pipeline.result import RenderResult

        return RenderResult
    raise AttributeError(f"module 'pyjulia4d' has no attribute {name!r}")
