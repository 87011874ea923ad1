"""Import the julia_fractal of a POV-Ray 3.7 scene as a pyjulia4d scene:
``pyjulia4d import-pov FILE.pov [-o SCENE.toml]``.

POV-Ray's scene language has no Python library; this is a small hand-written tokenizer
and recursive-descent reader of the part of it a julia_fractal scene uses: ``#version``,
``#include`` (noted, never read), ``#declare``/``#local`` of floats, vectors, colours and
julia_fractals, float and vector expressions (+ - * /, parentheses, ``< >`` vectors, x y z,
pi, image_width/height, the common float functions), ``camera``, ``light_source``,
``background``, ``julia_fractal`` and ``object { ID }`` of a declared one.  Everything
else that is a ``keyword { ... }`` block (other objects, global_settings, fog, ...) is
skipped and named in a comment of the scene written; anything it cannot read or map
exactly is refused with one line, ``FILE:LINE: reason``.

What POV-Ray does, and what pyjulia4d is told (POV-Ray 3.7 source: parser.cpp
Parse_Julia_Fractal and Parse_Camera, fractal.cpp, quaternion.cpp, hypercomplex.cpp):

* ``max_iteration N`` (default 20, floored, at least 1): POV-Ray tests |q_n| for
  n = 0 .. N-1 and never looks at q_N; pyjulia4d tests n = 0 .. max_iter.  So
  fractal.max_iter = N - 1 (N = 1, a ball, has no pyjulia4d equivalent: refused).
* The escape radius: hypercomplex 4 (Exit_Value 16), but quaternion
  sqrt(R^2 + 1e-7) with R = min(2, 1 + |c| + 1e-7) (Compute_BBox), not the documented 4.
  fractal.bailout gets that value.  With both, pyjulia4d's silhouette of the documentation
  example agrees with POV-Ray's (precision 1000) on every pixel of a 160x120 image.
* ``precision P`` (default 20, at least 1): POV-Ray's march steps at least 1/P.
  pyjulia4d's march stays its own (certified, finer), made no coarser than 1/P:
  ``de`` keeps epsilon 1e-3 unless 1/P is smaller; the fixed scan's z_resolution is
  raised to 2 x (bounding radius) x P if that exceeds 250.
* ``slice <n>, d``: POV-Ray normalises n and refuses |n|^2 or |n_t| below 1e-10, as here.
  It draws the 3D point X as the 4D point (X, (d - n_xyz.X) / n_t); pyjulia4d draws its
  camera coordinates p as R p + d n/|n| (camera.slice_rotation, an isometry).  The two are
  the same map when n has only a w component (any sign, any d): exact.  Otherwise the
  hyperplane is the same, and the eye, target and light are put at the same 4D points,
  but POV-Ray's picture is the section sheared by its projection along w and
  pyjulia4d's is undistorted: a warning says so.
* Camera (the 3.5+ rules: modifiers applied in POV-Ray's fixed order, whatever their
  order in the file): POV-Ray is left-handed, x right, y up, z into the screen, and so is
  pyjulia4d's frame with limbo = +w: right = cross4(forward, up, limbo) = up x forward,
  which is POV-Ray's right (sky x direction) - no coordinate is mirrored.  POV-Ray's
  ``angle`` is horizontal and sets |direction| = |right| / (2 tan(angle/2)); its vertical
  extent is |up| / |direction|, so camera.fov = 2 atan(|up| / (2 |direction|)) exactly,
  and the horizontal extent follows from the image's width/height, which equals POV-Ray's
  when |right| / |up| = width / height (else a warning: POV-Ray stretches its pixels).  A
  left-handed ``right`` (negative, e.g. ``right -x*4/3``) mirrors POV-Ray's image: that
  is limbo = -w here.  Default camera: location 0, direction z, up y, right 1.33 x.
* ``translate``/``rotate``/``scale``/``matrix`` on the julia_fractal: the inverse is applied
  to the camera and the light (exact for rotations, translations and uniform scales,
  mirrors included; others are refused).  On the camera and the light they are applied.
* pigment { color rgb <r,g,b> } -> shading.color; finish ambient, diffuse, specular,
  roughness (shininess = 1/roughness; POV-Ray's specular is Blinn-Phong too), with
  POV-Ray 3.7's defaults (0.1, 0.6, 0, 0.05) for what a given finish leaves out, and
  reflection (a number, or a grey) -> shading.reflection;
  the first light_source's position and colour -> shading.light (in the scene's
  coordinates) and shading.light_color, up to three more -> shading.lights (point lights,
  their colours), their shadows -> shading.shadow ("hard", or "none" for
  shadowless or no_shadow), shading.ao = 0 (POV-Ray has no ambient occlusion);
  background -> shading.background.  Colours are taken as linear (POV-Ray 3.7 with
  assumed_gamma 1.0, as pyjulia4d shades).  No pigment: pyjulia4d's colour is kept
  (POV-Ray would draw the object black); no light: pyjulia4d's default lighting.
"""
from __future__ import annotations

from pyjulia4d.interop.povray.mapping import Imported, pov_escape_radius
from pyjulia4d.interop.povray.reader import SceneReader
from pyjulia4d.interop.povray.expressions import rotation
from pyjulia4d.interop.povray.tokens import PovError, tokenize
from pyjulia4d.interop.povray.writer import check_toml_path, import_pov, read_pov, write_toml

__all__ = ["Imported", "pov_escape_radius", "SceneReader", "rotation", "PovError", "tokenize", "check_toml_path",
           "import_pov", "read_pov", "write_toml"]
