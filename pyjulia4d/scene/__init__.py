"""The scene: its sections and keys (model.py), their checks, the TOML and ``--set`` forms,
the measured quality presets (quality.py), keyframed animations (keyframes.py) and the key
listing (keys.py)."""
from pyjulia4d.fractal.registry import ALGEBRAS, FUNCTIONS, FUNCTIONS_OF, KINDS, march_method
from pyjulia4d.scene.model import COLORMAPS, Camera, Clip, Fractal, Image, Light, March, Normals, Render, Scene, Shading, Slice, key_names, valid_range
from pyjulia4d.scene.checks import SceneError
