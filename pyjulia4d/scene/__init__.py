"""The scene: its sections and keys (model.py), their checks, the TOML and ``--set`` forms,
the measured quality presets (quality.py), keyframed animations (keyframes.py) and the key
listing (keys.py)."""
from pyjulia4d.scene.model import (ALGEBRAS, COLORMAPS, FUNCTIONS, FUNCTIONS_OF, KINDS, Camera, Clip,  # noqa: F401
                                   Fractal, Image, Light, March, Normals, Render, Scene, SceneError, Shading, Slice,
                                   key_names, march_method, valid_range)
