"""Twin of kernels/path/path.cl in float64 numpy: the same plan (its camera, march, light,
shade and path records), the same random numbers, the same stages - so kernel and twin
trace the same paths, and differ only where float32 and float64 part ways (a ray grazing
the surface, a Russian roulette draw at its threshold).  ``trace`` gives one sample's
radiance and coverage of a set of pixels; ``film`` accumulates samples as path_film does.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from pyjulia4d.pipeline import colormap
from pyjulia4d.pipeline.codes import STATUS_HIT, STATUS_MISS
from pyjulia4d.pipeline.film import Film
from pyjulia4d.pipeline.plan import Plan
from pyjulia4d.reference.formula import formula_of
from pyjulia4d.reference.march import march
from pyjulia4d.reference.normals import clip_normals, normals_gradient, normals_jacobian
from pyjulia4d.reference.path_sample import (PI, bsdf_eval, cosine, disc, dot, ggx_half, local, path_rand, path_rand2,
                                             power_weight, spec_share, unit)
from pyjulia4d.reference.path_environment import EnvTwin
from pyjulia4d.reference.shade import orbit_iteration, orbit_trap


def light_weight(g, c, size: float, o, n, to_cam):
    """kernels/path/path.cl light_weight: what a light (a position g, or with c[3] != 0 a
    direction; size a sphere's radius or a sun's angular radius in degrees) can give a white
    matte surface at points o (k, 4) facing n (k, 3, camera coordinates): its luminance
    times min(max(n . l + sin(alpha), 0), 1), a bound on the cosine over the cone it fills."""
    dv = np.tile(g, (len(o), 1)) if c[3] != 0 else g - o
    dist = np.linalg.norm(dv, axis=1)
    ln = unit(to_cam(dv))
    if size <= 0:
        sin_a = np.zeros(len(o))
    elif c[3] != 0:
        sin_a = np.full(len(o), np.sin(min(size, 90.0) * PI / 180))
    else:
        sin_a = np.minimum(size / np.maximum(dist, size), 1.0)
    lum = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    return lum * np.clip(dot(n, ln) + sin_a, 0.0, 1.0)


def dim(bounce: int, k: int) -> int:
    """The random dimension of draw k at a hit (path.cl DIM)."""
    return 4 + 8 * bounce + k


class PathTwin:
    """The path tracer of one plan in float64."""

    def __init__(self, plan: Plan):
        self.plan = plan
        self.F = formula_of(plan.fractal)
        self.march = dataclasses.replace(plan.march, near=-1.0, far=-1.0)
        self.planes = list(plan.clip.planes)
        sa = plan.shade
        self.lut = colormap.table_of(sa.colormap).astype(np.float64) if sa.colormap is not None else None
        pa = plan.path
        self.env = EnvTwin(pa.environment, pa.env_x, pa.env_y, pa.env_z) if pa.environment is not None else None

    def sky_radiance(self, d4, sky):
        """SKY_RADIANCE: the sky colour, times the environment's image where there is one."""
        return sky * (self.env.radiance(d4) if self.env is not None else 1.0)

    def sky_pdf(self, n, d3):
        """SKY_PDF: the sky's own density of drawing camera-space direction d3 at normal n."""
        if self.env is not None:
            return self.env.pdf(self.to_world(d3))
        return np.maximum(dot(n, d3), 0) / PI

    def sky_sample(self, n, u1, u2):
        if self.env is not None:
            return unit(self.to_cam(self.env.sample(u1, u2)))
        return cosine(n, u1, u2)

    def to_cam(self, a):
        f = self.plan.frame
        return np.stack([a @ f.right, a @ f.up, -(a @ f.forward)], axis=-1)

    def to_world(self, a):
        f = self.plan.frame
        return a[:, :1] * f.right + a[:, 1:2] * f.up - a[:, 2:3] * f.forward

    def camera(self, px, py, s: int):
        """path_camera: the rays of sample s of pixels (px, py)."""
        p, fr = self.plan, self.plan.frame
        W, H = p.image.width, p.image.height
        key = (py.astype(np.uint64) * W + px).astype(np.uint32)
        ox, oy = path_rand2(key, s, 0)
        u = (2 * (px + ox) / W - 1) * fr.tan_half_fov * (W / H)
        v = (1 - 2 * (py + oy) / H) * fr.tan_half_fov
        d = fr.forward + u[:, None] * fr.right + v[:, None] * fr.up
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        o = np.tile(np.asarray(fr.position, np.float64), (len(px), 1))
        if p.path.aperture > 0:
            l = p.path.aperture * disc(*path_rand2(key, s, 2))
            f = o + d * (p.path.focus / (d @ fr.forward))[:, None]
            o = o + l[:, :1] * fr.right + l[:, 1:2] * fr.up
            d = (f - o) / np.linalg.norm(f - o, axis=1, keepdims=True)
        return key, o, d

    def hits(self, o, d):
        """The march, the normals (path_plan.bounce_normals), the cut faces'."""
        p = self.plan
        guard = np.zeros(len(o), np.int64)
        bracket = np.full(len(o), np.inf)
        depth, point, status, _ = march(o, d, self.march, guard, bracket, self.F, self.planes)
        if p.path.normals == "jacobian":
            n = normals_jacobian(point, status, p.frame, self.march, guard, self.F)
        else:
            n = normals_gradient(point, status, p.frame, self.march, p.normals_args, guard, self.F)
        return depth, point, status, bracket, clip_normals(guard, status, p.frame, self.planes, n)

    def base(self, pt, d, bracket):
        """hit_base: (the scene's colour or the colour map's at the hit's colour value, that
        value; 0 for the flat colour)."""
        sa, la, ma = self.plan.shade, self.plan.light_args, self.march
        if self.lut is None:
            return np.clip(np.tile(np.asarray(sa.color[:3], np.float64), (len(pt), 1)), 0, 1), np.zeros(len(pt))
        if la.coloring == "iteration":
            val = orbit_iteration(pt + bracket[:, None] * d, ma.c, ma.max_iter, ma.bailout, self.F)
        elif la.coloring == "trap":
            val = orbit_trap(pt, ma.c, ma.max_iter, ma.bailout, la.trap, self.F)
        else:
            val = np.clip(0.5 + pt[:, 3] / ma.radius, 0, 1)
        x = np.clip(val, 0, 1) * (len(self.lut) - 1)
        k = np.minimum(x.astype(int), len(self.lut) - 2)
        t = (x - k)[:, None]
        return np.clip(self.lut[k, :3] * (1 - t) + self.lut[k + 1, :3] * t, 0, 1), np.clip(val, 0, 1)

    def trace(self, px, py, s: int):
        """Sample s of pixels (px, py): (radiance (n, 3), coverage (n,), first hits' colour (n, 3))."""
        p = self.plan
        pa, sa, la = p.path, p.shade, p.light_args
        key, o, d = self.camera(np.asarray(px), np.asarray(py), s)
        n = len(key)
        T = np.ones((n, 3))
        wsky = np.ones(n)
        alive = np.ones(n, bool)
        R, A, albedo = np.zeros((n, 3)), np.zeros(n), np.zeros((n, 3))
        self.first_normal = np.zeros((n, 3))
        sky = np.asarray(pa.sky[:3], np.float64)
        sky_on = sky.sum() > 0
        geo = [np.asarray(sa.light, np.float64)] + [np.asarray(g, np.float64) for g in sa.lights_geo[:sa.n_lights]]
        rgb = [np.append(np.asarray(sa.light_color[:3], np.float64), 0.0)] + \
              [np.asarray(c, np.float64) for c in sa.lights_rgb[:sa.n_lights]]
        key_on = int(np.sum(rgb[0][:3]) > 0)   # a black key light is not drawn
        sizes = [float(np.float32(sa.light_radius))] + [float(x) for x in np.asarray(sa.lights_size, np.float32)[:sa.n_lights]]
        n_point = len(geo) - 1 + key_on
        n_all = n_point + int(sky_on)
        for b in range(pa.bounces):
            depth, pt, st, bracket, nrm = self.hits(o, d)
            miss = alive & (st == STATUS_MISS)
            R[miss] += (np.asarray(sa.background[:3]) if b == 0 else
                        T[miss] * self.sky_radiance(d[miss], sky) * wsky[miss, None])
            hit = alive & (st == STATUS_HIT)
            if b == 0:
                A[hit] = 1.0
            alive = hit
            k = np.nonzero(hit)[0]
            if k.size == 0:
                break
            ks, dk = key[k], d[k]
            v = -self.to_cam(dk)
            nn = unit(nrm[k])
            nn = np.where((dot(nn, v) < 0)[:, None], -nn, nn)
            n4 = self.to_world(nn)
            base, val = self.base(pt[k], dk, bracket[k])
            R[k] += T[k] * pa.emission * (1 - val)[:, None] * base   # the surface's own light
            if b == 0:
                albedo[k] = base
                self.first_normal[k] = nn
            nv = np.maximum(dot(nn, v), 1e-6)
            ps = spec_share(base, pa.metallic, pa.f0s, nv)
            ob = pt[k] + la.bias * n4
            # next-event estimation: one light, chosen by what each can give the point (path.cl)
            if n_all == 0:   # nothing lights the scene
                break
            wts = np.stack([light_weight(geo[i], rgb[i], sizes[i], ob, nn, self.to_cam) for i in range(len(geo))]
                           + [np.full(k.size, pa.sky_weight if sky_on else 0.0)], axis=1)
            w_all = wts.sum(axis=1)
            u_pick = path_rand(ks, s, dim(b, 2)) * w_all
            cum = np.cumsum(wts, axis=1)
            # the first light whose running sum passes u (path.cl's walk: key, extra lights, sky);
            # -1 where none can reach the point
            j = np.where((u_pick[:, None] < cum).any(axis=1), np.argmax(u_pick[:, None] < cum, axis=1), -1)
            j = np.where((j < 0) & (wts[:, -1] > 0), len(geo), j)
            w_j = np.where(j >= 0, wts[np.arange(k.size), np.maximum(j, 0)], 1.0)
            with np.errstate(divide="ignore", invalid="ignore"):
                p_sky = np.where(w_all > 0, wts[:, -1] / np.where(w_all > 0, w_all, 1.0), 0.0)
            l = np.zeros((k.size, 3))
            le = np.zeros((k.size, 3))
            dist = np.full(k.size, np.inf)
            wl = np.ones(k.size)
            for i in range(len(geo)):
                m = j == i
                g, c, size = geo[i], rgb[i], sizes[i]
                lv = np.tile(g, (k.size, 1)) if c[3] != 0 else g - ob
                l[m] = unit(self.to_cam(lv[m]))
                if c[3] == 0:
                    dist[m] = np.linalg.norm(lv[m], axis=1)
                if size > 0 and m.any():   # a sphere or a sun: a direction in its cone (path.cl)
                    if c[3] != 0:
                        cmax = np.full(m.sum(), np.cos(min(size, 90.0) * PI / 180))
                    else:
                        q = size / np.maximum(dist[m], size)
                        cmax = np.sqrt(np.maximum(1 - q * q, 0))
                    uc, uphi = path_rand2(ks[m], s, dim(b, 0))
                    ct = 1 - uc * (1 - cmax)
                    st = np.sqrt(np.maximum(1 - ct * ct, 0))
                    phi = 2 * PI * uphi
                    l[m] = unit(local(l[m], st * np.cos(phi), st * np.sin(phi), ct))
                    dist[m] = np.maximum(dist[m] - size, 0)
                le[m] = PI * c[:3]
            m = j == len(geo)
            if m.any():
                l[m] = self.sky_sample(nn[m], *path_rand2(ks[m], s, dim(b, 0)))
                pl = self.sky_pdf(nn[m], l[m])
                sl = self.sky_radiance(self.to_world(l[m]), sky)
                with np.errstate(divide="ignore", invalid="ignore"):
                    le[m] = np.where((pl > 0)[:, None], sl / np.where(pl > 0, pl, 1.0)[:, None], 0.0)
                _, pb = bsdf_eval(nn[m], v[m], l[m], base[m], pa.metallic, pa.f0s, pa.alpha2, ps[m])
                wl[m] = 1.0 if b + 1 >= pa.bounces else power_weight(pl * p_sky[m], pb)
            fl, _ = bsdf_eval(nn, v, l, base, pa.metallic, pa.f0s, pa.alpha2, ps)
            add = T[k] * fl * le * (wl * w_all / w_j)[:, None]
            lit = (j >= 0) & (fl.sum(axis=1) > 0)
            if lit.any():
                ls = np.nonzero(lit)[0]
                sd, _, sst, _, _ = self.hits(ob[ls], self.to_world(l[ls]))
                reach = (sst == STATUS_MISS) | ((sst == STATUS_HIT) & (sd > dist[ls]))
                R[k[ls[reach]]] += add[ls[reach]]
            if b + 1 >= pa.bounces:
                break
            u1, u2 = path_rand2(ks, s, dim(b, 4))
            spec = path_rand(ks, s, dim(b, 3)) < ps
            h = ggx_half(nn, pa.alpha2, u1, u2)
            nd = np.where(spec[:, None], 2 * dot(v, h)[:, None] * h - v, cosine(nn, u1, u2))
            nd = unit(nd)
            fb, pb = bsdf_eval(nn, v, nd, base, pa.metallic, pa.f0s, pa.alpha2, ps)
            go = (pb > 0) & (fb.sum(axis=1) > 0)
            with np.errstate(divide="ignore", invalid="ignore"):
                w = T[k] * np.where(go[:, None], fb / np.where(go, pb, 1.0)[:, None], 0.0)
            if b >= 2:
                q = np.clip(w.max(axis=1), 0.05, 0.95)
                go &= path_rand(ks, s, dim(b, 6)) < q
                w = w / q[:, None]
            psky = self.sky_pdf(nn, nd) * p_sky if sky_on else np.zeros(k.size)
            alive = np.zeros(n, bool)
            alive[k[go]] = True
            T[k] = w
            wsky[k] = power_weight(pb, psky)
            o = o.copy()
            d = d.copy()
            o[k] = ob
            d[k] = self.to_world(nd)
        return R, A, albedo


def film(plan: Plan, px, py, samples: int | None = None) -> tuple[np.ndarray, np.ndarray, Film]:
    """Pixels (px, py) through ``samples`` paths each (image.samples where None; no noise
    target): (mean radiance (n, 3), mean coverage (n,), the film's statistics, shaped (n,))."""
    twin = PathTwin(plan)
    S = plan.path.samples if samples is None else samples
    n = len(px)
    mean, m2 = np.zeros((n, 4)), np.zeros((n, 4))
    alb = np.zeros((n, 3))
    first = plan.path.first_sample
    for s in range(S):
        R, A, a = twin.trace(px, py, first + s)
        x = np.concatenate([R, A[:, None]], axis=1)
        d = x - mean
        m1 = mean + d / (s + 1)
        lum = lambda c: c[:, 0] * 0.2126 + c[:, 1] * 0.7152 + c[:, 2] * 0.0722
        m2[:, :3] += d[:, :3] * (x[:, :3] - m1[:, :3])
        m2[:, 3] += (lum(x) - lum(mean)) * (lum(x) - lum(m1))
        mean = m1
        alb += (a - alb) / (s + 1)
    film = Film.from_moments(m2, alb, np.full(n, S, np.int32), mean[:, 3])
    film.normal = nrm.astype(np.float32)
    return mean[:, :3], mean[:, 3], film
