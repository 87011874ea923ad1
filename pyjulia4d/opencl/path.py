"""The path tracer's pass on one device (shading.integrator = "path"): every tile of the
plan through image.samples paths per pixel, each a camera ray and up to shading.bounces
hits, every ray of them - the bounces' and the shadow rays - marched by the render's own
march (kernels/path/path.cl says what each stage does).  The tile's film (each pixel's
mean, squared deviations, first-hit colour and sample count) stays on the device until the
tile's last sample; ``PathFilm`` holds the region's.  Everything read comes from the plan
(pipeline/plan.py, pipeline/path_plan.py); the float64 twin is reference/path.py.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pyopencl as cl
import pyopencl.array as cla

from pyjulia4d.opencl import build
from pyjulia4d.opencl.records import Packed, Precision, float4
from pyjulia4d.opencl.runner import constant, launch, march_items, queue_for
from pyjulia4d.pipeline import colormap, signatures as sig
from pyjulia4d.pipeline.film import Film
from pyjulia4d.pipeline.plan import Plan, Tile
from pyjulia4d.pipeline.store import new_zeros

MARCH_OUT = ("depth", "point", "status", "samples", "flags", "bracket", "unresolved")


class PathFilm:
    """The region's film: the mean colour and coverage, the variance of each mean (per
    channel and of the luminance), the first hits' colour (the denoiser's albedo) and the
    samples each pixel took."""

    def __init__(self, height: int, width: int):
        self.mean = new_zeros((height, width, 4), np.float32)
        self.m2 = new_zeros((height, width, 4), np.float32)
        self.albedo = new_zeros((height, width, 3), np.float32)
        self.normal = new_zeros((height, width, 3), np.float32)
        self.count = new_zeros((height, width), np.int32)

    def file(self, dst, mean, m2, albedo, normal, count) -> None:
        self.mean[dst] = mean
        self.m2[dst] = m2
        self.albedo[dst] = albedo[..., :3]
        self.normal[dst] = normal[..., :3]
        self.count[dst] = count

    def result(self) -> Film:
        film = Film.from_moments(self.m2, self.albedo, self.count, self.mean[..., 3])
        film.normal = self.normal
        return film


class PathRunner:
    """The path tracer's program and kernels for one plan on one device, and one tile's buffers."""

    def __init__(self, plan: Plan, dev: cl.Device):
        self.plan = plan
        self.ctx, self.queue = queue_for(dev)
        self.pr = pr = Precision(plan.double)
        cfg, mcfg = plan.path_config, plan.path_march_config
        self.prg = build.program(self.ctx, cfg)
        self.march_prg = build.program(self.ctx, mcfg)
        rec = plan.records()
        # bounces and shadow rays start anywhere in the ball: its own entry and exit, whatever
        # march.near and march.far the camera's rays take
        rec["march"] = dataclasses.replace(plan.march, near=-1.0, far=-1.0)
        sa = plan.shade
        lut = colormap.table_of(sa.colormap) if sa.colormap is not None else np.zeros((2, 4), np.float32)
        lights = dict(lights_geo=constant(self.queue, np.array([pr.v4(g) for g in sa.lights_geo])),
                      lights_rgb=constant(self.queue, np.array([float4(c) for c in sa.lights_rgb])),
                      lights_size=constant(self.queue, np.asarray(sa.lights_size, np.float32)))
        self.k = {name: build.kernel(self.prg, name) for name in ("path_camera", "path_bounce", "path_shadow",
                                                                  "path_film")}
        self.k["march"] = build.kernel(self.march_prg, "march")
        self.march_args = Packed(sig.MARCH, rec, pr, mcfg.defines)
        self.lanes, self.packets = plan.lanes, plan.march_packets
        # the bounces' normals: the march's program's (in its packets) where it has them
        normals = sig.NORMALS[plan.path.normals]
        own = f"normals/{plan.path.normals}" in cfg.pieces
        self.k["normals"] = build.kernel(self.prg if own else self.march_prg, normals.kernel)
        self.normals_lanes = 1 if own else self.lanes
        self.normals_args = Packed(normals, rec, pr)
        self.clip_args = None
        if plan.clip.planes:
            self.k["clip"] = build.kernel(self.prg, "clip_normals")
            self.clip_args = Packed(sig.CLIP, rec, pr)
        self.camera_args = Packed(sig.PATH_CAMERA, rec, pr)
        env = plan.path.environment
        if env is not None:   # shading.environment's image and its distribution (pipeline/environment.py)
            lights.update(env=constant(self.queue, env.image.view(cl.cltypes.float4).reshape(-1)),
                          env_rows=constant(self.queue, env.marginal.astype(pr.scalar)),
                          env_cols=constant(self.queue, env.conditional.astype(pr.scalar).ravel()))
        self.bounce_args = Packed(sig.PATH_BOUNCE, rec, pr, cfg.defines, lut=constant(
            self.queue, lut.astype(np.float32).view(cl.cltypes.float4).ravel()), n_lut=len(lut), **lights)
        self.shadow_args = Packed(sig.PATH_SHADOW, rec, pr)
        self.film_args = Packed(sig.PATH_FILM, rec, pr)
        n = max(t.n for t in plan.tiles)
        m = n * plan.path.batch   # the paths of a launch: batch samples of each pixel
        q = self.queue
        self.b = {k: cla.empty(q, m, pr.vec_dtype) for k in ("origins", "dirs", "s_origins", "s_dirs", "point",
                                                              "normal")}
        self.b.update({k: cla.empty(q, m, pr.scalar) for k in ("depth", "bracket", "unresolved")})
        self.b.update({k: cla.empty(q, m, np.int32) for k in ("status", "samples", "flags")})
        self.b.update({k: cla.empty(q, m, cl.cltypes.float4) for k in ("thru", "rad", "pending", "albedo",
                                                                      "first_normal")})
        self.b["film_count"] = cla.empty(q, n, np.int32)
        self.b.update({k: cla.empty(q, n, cl.cltypes.float4) for k in ("film_mean", "film_m2", "film_albedo",
                                                                      "film_normal")})

    def march(self, n: int, tile: Tile, origins: str, dirs: str) -> list:
        """The march of n rays: the batch's copies of the tile, one under the other (packets of
        neighbouring pixels' rays, as the camera's march)."""
        b = self.b
        return [launch(self.queue, self.k["march"], n, *self.march_args(
            tile_w=tile.aw, origins=b[origins], dirs=b[dirs], **{k: b[k] for k in MARCH_OUT}),
            items=march_items(n, tile.aw, self.lanes, self.packets))]

    def normals(self, n: int) -> list:
        b, q = self.b, self.queue
        ev = [launch(q, self.k["normals"], n, *self.normals_args(point=b["point"], status=b["status"],
                                                                 normal=b["normal"], flags=b["flags"]),
                     lanes=self.normals_lanes)]
        if self.clip_args is not None:
            ev.append(launch(q, self.k["clip"], n, *self.clip_args(flags=b["flags"], status=b["status"],
                                                                   normal=b["normal"])))
        return ev

    def sample(self, tile: Tile, s: int, k: int) -> list:
        """Queue samples ``s`` .. s + k - 1 of every pixel of ``tile``: their paths, then the film."""
        b, q, npix = self.b, self.queue, tile.n
        n = npix * k
        place = dict(n_pix=npix, tile_w=tile.aw, x0=tile.ax0, y0=tile.ay0)
        ev = [launch(q, self.k["path_camera"], n, *self.camera_args(
            **place, sample=s, film_m2=b["film_m2"], film_count=b["film_count"], origins=b["origins"],
            dirs=b["dirs"], thru=b["thru"], rad=b["rad"]))]
        for bounce in range(self.plan.path.bounces):
            ev += self.march(n, tile, "origins", "dirs")
            ev += self.normals(n)
            ev.append(launch(q, self.k["path_bounce"], n, *self.bounce_args(
                **place, sample=s, bounce=bounce, status=b["status"], point=b["point"], normal=b["normal"],
                bracket=b["bracket"], origins=b["origins"], dirs=b["dirs"], thru=b["thru"], rad=b["rad"],
                pending=b["pending"], s_origins=b["s_origins"], s_dirs=b["s_dirs"], albedo=b["albedo"],
                first_normal=b["first_normal"])))
            ev += self.march(n, tile, "s_origins", "s_dirs")
            ev.append(launch(q, self.k["path_shadow"], n, *self.shadow_args(
                status=b["status"], depth=b["depth"], pending=b["pending"], rad=b["rad"])))
        ev.append(launch(q, self.k["path_film"], npix, *self.film_args(
            batch=k, rad=b["rad"], albedo=b["albedo"], first_normal=b["first_normal"], film_mean=b["film_mean"],
            film_m2=b["film_m2"], film_albedo=b["film_albedo"], film_normal=b["film_normal"],
            film_count=b["film_count"])))
        return ev

    def tile(self, tile: Tile, on_sample=None) -> tuple[dict[str, np.ndarray], list]:
        """Every sample of ``tile``'s pixels: its film over its box, shaped (ah, aw[, 4]), and
        the kernels' events.  ``on_sample(tile)`` is called for each sample done, as each
        launch's samples are done."""
        b, q, n = self.b, self.queue, tile.n
        for k in ("film_mean", "film_m2", "film_albedo", "film_normal", "film_count"):
            cl.enqueue_fill_buffer(q, b[k].data, np.uint8(0), 0, b[k].nbytes)
        events = []
        first, total, batch = self.plan.path.first_sample, self.plan.path.samples, self.plan.path.batch
        for s in range(first, first + total, batch):
            k = min(batch, first + total - s)
            ev = self.sample(tile, s, k)
            q.flush()
            cl.wait_for_events([ev[-1]])
            events += ev
            for _ in range(k if on_sample is not None else 0):
                on_sample(tile)
        shape = (tile.ah, tile.aw)
        out = {k: b[k][:n].get().view(np.float32).reshape(*shape, 4)
               for k in ("film_mean", "film_m2", "film_albedo", "film_normal")}
        out["film_count"] = b["film_count"][:n].get().reshape(shape)
        return out, events


def path_pass(plan: Plan, dev: cl.Device, at, events: list, bar) -> PathFilm:
    """The path tracer over the plan's region, tile by tile: its film.  ``at(tile)`` gives
    the tile's place in the region's arrays (Filing.at); ``bar`` moves a tile's pixels a sample."""
    _, _, W, H = plan.region
    film = PathFilm(H, W)
    runner = PathRunner(plan, dev)
    for t in plan.tiles:
        got, ev = runner.tile(t, on_sample=lambda tile: bar.update(tile.w * tile.h))
        events += ev
        own = t.own()
        film.file(at(t), got["film_mean"][own], got["film_m2"][own], got["film_albedo"][own],
                  got["film_normal"][own], got["film_count"][own])
    return film
