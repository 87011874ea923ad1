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

from typing import Any, Callable

import numpy as np

from pyjulia4d.geometry.navigate import frame
from pyjulia4d.geometry.camera import slice_map

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


Band = Callable[[slice], np.ndarray]   # a channel as a function of a band of rows


def exr_output(result: Any, scene: Any) -> tuple[dict[str, np.ndarray | Band], dict[str, Any]]:
    """(channels, header entries) of ``result`` in the scene's image.exr layout (see the
    module's docstring).  A channel is an (H, W) array, or where the layout computes it, a
    function of a band of rows giving that band (the writer's bands: a 3840x2160 image's
    float64 temporaries need not be held whole)."""
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
    ch: dict[str, np.ndarray | Band] = {}
    if result.color is not None and result.alpha is not None:
        back = getattr(result, "backdrop", None)
        bg = np.asarray(scene.shading.background, np.float32)

        def combined(k: int) -> Band:
            # premultiplied whatever the background: rgb - (1 - a) background, per pixel for a backdrop
            return lambda rows: (np.asarray(result.color[rows, :, k], np.float32)
                                 - (1.0 - np.asarray(result.alpha[rows], np.float32))
                                 * (bg[k] if back is None else back[rows, :, k]))
        for k, name in enumerate("RGB"):
            ch[f"ViewLayer.Combined.{name}"] = combined(k)
        ch["ViewLayer.Combined.A"] = result.alpha
    f, r, u, _, _ = frame(scene.camera)
    rot, offset = slice_map(scene)
    if result.depth is not None:
        # along the view axis: the depth along each pixel's centre ray times the ray's cosine
        # with the view direction, 1 / |forward + u right + v up| (kernels/rays.cl)
        h, w = result.depth.shape
        t = np.tan(np.radians(scene.camera.fov) / 2)
        pu = (2 * (np.arange(w) + 0.5) / scene.image.width - 1) * t * scene.image.width / scene.image.height
        pv = (1 - 2 * (np.arange(h) + 0.5) / scene.image.height) * t

        def view_depth(rows: slice) -> np.ndarray:
            depth = np.asarray(result.depth[rows], np.float64)
            cos = 1 / np.sqrt(1 + pu[None, :] ** 2 + pv[rows, None] ** 2)
            return np.where(np.isfinite(depth), depth * cos, MISS_DEPTH).astype(np.float32)
        ch["ViewLayer.Depth.Z"] = view_depth
    if result.position is not None:
        def position(k: int) -> Band:
            def band(rows: slice) -> np.ndarray:
                raw = np.asarray(result.position[rows])
                scene_p = (np.nan_to_num(raw.astype(np.float64)) - offset) @ rot   # rot^T (p - offset)
                miss = ~np.all(np.isfinite(raw), axis=-1)
                return np.where(miss, 0.0, scene_p[..., k]).astype(np.float32)
            return band
        for k, name in enumerate("XYZ"):
            ch[f"ViewLayer.Position.{name}"] = position(k)
    if result.normal is not None:
        def normal(k: int) -> Band:
            # camera coordinates (right, up, towards the eye) -> the scene's
            axis = np.array([r[k], u[k], -f[k]])
            return lambda rows: (np.asarray(result.normal[rows], np.float64) @ axis).astype(np.float32)
        for k, name in enumerate("XYZ"):
            ch[f"ViewLayer.Normal.{name}"] = normal(k)
    if result.bracket is not None and result.depth is not None:
        for key, src in (("Bracket", result.bracket), ("Unresolved", result.unresolved)):
            if src is not None:
                def reach(rows: slice, src=src) -> np.ndarray:
                    hit = np.isfinite(result.bracket[rows])
                    return np.where(hit, np.nan_to_num(src[rows], posinf=0.0), 0.0).astype(np.float32)
                ch[f"ViewLayer.{key}.Z"] = reach
    film = getattr(result, "film", None)
    if film is not None:   # a path-traced render's: the denoiser's guide and the noise, per channel
        for k, name in enumerate("RGB"):
            ch[f"ViewLayer.Denoising Albedo.{name}"] = np.ascontiguousarray(film.albedo[..., k])
            ch[f"ViewLayer.Variance.{name}"] = np.ascontiguousarray(film.variance[..., k])
        if film.normal is not None:   # the mean first-hit normal, in the scene's x, y, z as Normal is
            for k, name in enumerate("XYZ"):
                axis = np.array([r[k], u[k], -f[k]])
                ch[f"ViewLayer.Denoising Normal.{name}"] = (film.normal.astype(np.float64) @ axis).astype(np.float32)
        if film.noisy is not None:   # image.denoise: Combined is the denoised picture, this the one before
            for k, name in enumerate("RGB"):
                ch[f"ViewLayer.Noisy Image.{name}"] = np.ascontiguousarray(film.noisy[..., k])
    return ch, header
