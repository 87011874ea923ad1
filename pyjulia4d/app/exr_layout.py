"""What an EXR holds, by image.exr: pyjulia4d's own channels, or the passes compositors read.

- ``"pyjulia4d"`` (the default): R, G, B, A as rendered (the colour is the background where
  nothing was hit, alpha 0 there), Z along the unit 4D ray (+inf on a miss), Z.bracket,
  Z.unresolved, N.X/Y/Z in camera coordinates (x right, y up, z towards the eye), P.X/Y/Z/W the
  4D world point (NaN on a miss) - the spaces named in the header.
- ``"compositing"``: Blender's multilayer names, which Blender's compositor reads as passes
  and Nuke as layers:
  - ``ViewLayer.Combined.R/G/B/A``: RGBA premultiplied by alpha whatever the background,
    rgb - (1 - a) background;
  - ``ViewLayer.Depth.Z``: distance along the view axis, (p - eye) . forward, as Blender writes
    its Depth pass, with 1e10 where nothing was hit (Blender's background depth);
  - ``ViewLayer.Normal.X/Y/Z`` and ``ViewLayer.Position.X/Y/Z``: the normal and the hit point
    in one space, the scene's own x, y, z (the coordinates camera.position is given in; the
    w coordinate dropped), 0 where nothing was hit;
  - ``ViewLayer.Bracket.Z`` and ``ViewLayer.Unresolved.Z``: the certified depth bracket and
    the unproven reach in front (0 on a miss).

Both carry the camera as OpenEXR's standard ``worldToCamera`` and ``worldToNDC`` (M44f, row
vectors: p' = p M, then divided by its w), the scene's x, y, z as the world, where the camera
sees a 3D space of the scene - position, target and up with w = 0 and limbo along w: the usual
3D camera.  A camera turned through w sees a 3D space that is no coordinate space of the
scene's, and the header says so instead.  Camera space is OpenEXR's (RenderMan's): x right, y
up, z along the view; NDC x from 0 at the image's left edge to 1 at its right, y from 0 at the
top to 1 at the bottom."""
from __future__ import annotations

from typing import Any

import numpy as np

from pyjulia4d.geometry.navigate import frame
from pyjulia4d.geometry.camera import slice_rotation
from pyjulia4d.geometry.vec4 import unit

LAYOUTS = ("pyjulia4d", "compositing")
MISS_DEPTH = 1e10          # Blender's depth where nothing was hit
THREE_D = 1e-9             # a frame vector's w below this counts as 0


def camera_matrices(scene: Any) -> dict[str, np.ndarray] | None:
    """{"worldToCamera", "worldToNDC"} (float32 4x4, row vectors) of the scene's camera in the
    scene's x, y, z; None where the camera sees no 3D coordinate space of the scene."""
    cam = scene.camera
    f, r, u, limbo, _ = frame(cam)
    if abs(cam.position[3]) > THREE_D or max(abs(f[3]), abs(r[3]), abs(u[3])) > THREE_D:
        return None
    eye = np.asarray(cam.position[:3], float)
    to_cam = np.eye(4)
    for k, axis in enumerate((r[:3], u[:3], f[:3])):
        to_cam[:3, k] = axis
        to_cam[3, k] = -eye @ axis
    t = np.tan(np.radians(cam.fov) / 2)
    aspect = scene.image.width / scene.image.height
    # camera (x, y, z) -> (x / (2 t a) + z / 2, -y / (2 t) + z / 2, z, z): divided by w = z, NDC
    project = np.array([[0.5 / (t * aspect), 0, 0, 0],
                        [0, -0.5 / t, 0, 0],
                        [0.5, 0.5, 1, 1],
                        [0, 0, 0, 0]])
    return {"worldToCamera": to_cam.astype(np.float32), "worldToNDC": (to_cam @ project).astype(np.float32)}


def exr_output(result: Any, scene: Any) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """(channels, header entries) of ``result`` in the scene's image.exr layout (see the
    module's docstring)."""
    layout = scene.image.exr
    header: dict[str, Any] = {"pyjulia4d.exr_layout": layout}
    mats = camera_matrices(scene)
    if mats is None:
        header["pyjulia4d.camera_matrices"] = ("none: the camera sees a 3D space turned through w, no coordinate "
                                               "space of the scene's")
    else:
        header.update(mats)
    if layout == "pyjulia4d":
        header["pyjulia4d.normal_space"] = "camera: N.X right, N.Y up, N.Z towards the eye"
        header["pyjulia4d.position_space"] = "world: the 4D hit point, NaN on a miss"
        return result.exr_channels(), header
    header["pyjulia4d.normal_space"] = "scene: x, y, z (w dropped), 0 on a miss"
    header["pyjulia4d.position_space"] = "scene: x, y, z (w dropped), 0 on a miss"
    header["pyjulia4d.depth"] = f"distance along the view axis; {MISS_DEPTH:g} on a miss"
    ch: dict[str, np.ndarray] = {}
    if result.color is not None and result.alpha is not None:
        a = np.asarray(result.alpha, np.float32)
        bg = np.asarray(scene.shading.background, np.float32)
        premult = np.asarray(result.color, np.float32) - (1.0 - a)[..., None] * bg
        for k, name in enumerate("RGB"):
            ch[f"ViewLayer.Combined.{name}"] = premult[..., k]
        ch["ViewLayer.Combined.A"] = a
    hit = np.isfinite(result.bracket) if result.bracket is not None else None
    f, r, u, _, _ = frame(scene.camera)
    rot = slice_rotation(scene.slice.normal)
    offset = scene.slice.distance * unit(scene.slice.normal)
    if result.depth is not None:
        # along the view axis: the depth along each pixel's centre ray times the ray's cosine
        # with the view direction, 1 / |forward + u right + v up| (kernels/rays.cl)
        depth = np.asarray(result.depth, np.float64)
        h, w = depth.shape
        t = np.tan(np.radians(scene.camera.fov) / 2)
        pu = (2 * (np.arange(w) + 0.5) / scene.image.width - 1) * t * scene.image.width / scene.image.height
        pv = (1 - 2 * (np.arange(h) + 0.5) / scene.image.height) * t
        cos = 1 / np.sqrt(1 + pu[None, :] ** 2 + pv[:, None] ** 2)
        ch["ViewLayer.Depth.Z"] = np.where(np.isfinite(depth), depth * cos, MISS_DEPTH).astype(np.float32)
    if result.position is not None:
        p = np.nan_to_num(np.asarray(result.position, np.float64))
        scene_p = (p - offset) @ rot   # rot^T (p - offset), row by row
        miss = ~np.all(np.isfinite(np.asarray(result.position)), axis=-1)
        for k, name in enumerate("XYZ"):
            ch[f"ViewLayer.Position.{name}"] = np.where(miss, 0.0, scene_p[..., k]).astype(np.float32)
    if result.normal is not None:
        n = np.asarray(result.normal, np.float64)
        # camera coordinates (right, up, towards the eye) -> the scene's
        scene_n = n[..., :1] * r + n[..., 1:2] * u - n[..., 2:3] * f
        for k, name in enumerate("XYZ"):
            ch[f"ViewLayer.Normal.{name}"] = scene_n[..., k].astype(np.float32)
    for key, src in (("Bracket", result.bracket), ("Unresolved", result.unresolved)):
        if src is not None and hit is not None and result.depth is not None:
            ch[f"ViewLayer.{key}.Z"] = np.where(hit, np.nan_to_num(src, posinf=0.0), 0.0).astype(np.float32)
    return ch, header
