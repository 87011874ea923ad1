"""The scene: its sections (model.py), every key's checker and range (ranges.py, checks.py), the rules across
keys (rules.py), the TOML and ``--set`` forms (text.py), the measured quality presets
(quality.py), keyframed animations (keyframes.py) and the key listing (keys.py)."""
from pyjulia4d.fractal.registry import ALGEBRAS, FUNCTIONS, FUNCTIONS_OF, KINDS, march_method
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Camera, Clip, Fractal, Image, March, Normals, Render, Scene, Shading, Slice
from pyjulia4d.scene.ranges import COLORMAPS, Light, key_names, valid_range

__all__ = ["ALGEBRAS", "FUNCTIONS", "FUNCTIONS_OF", "KINDS", "march_method", "SceneError", "COLORMAPS", "Camera",
           "Clip", "Fractal", "Image", "Light", "March", "Normals", "Render", "Scene", "Shading", "Slice",
           "key_names", "valid_range"]
