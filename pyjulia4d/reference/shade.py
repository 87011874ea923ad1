"""float64 twins of kernels/shade/light.cl and kernels/shade/shade.cl."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pyjulia4d.geometry.camera import Frame
from pyjulia4d.pipeline.codes import STATUS_HIT
from pyjulia4d.pipeline.colormap import lookup
# imported by the package at its end, once these are defined
from pyjulia4d.reference.iterate import dot4, julia_distance_formula, julia_inside
from pyjulia4d.reference.normals import to_camera
from pyjulia4d.reference.formula import QUATERNION_SQR, Formula

if TYPE_CHECKING:
    from pyjulia4d.pipeline.records import LightArgs, MarchArgs, ShadeArgs


def shadow_ray(o, l, tmax, c, max_iter, bailout, radius, step, softness, max_steps, soft,
               F: Formula = QUATERNION_SQR, lit=None):
    """Visibility of the light along o + t l (shade/light.cl shadow_ray): steps of max(d, step)
    by the estimate where F has one (soft: min(k 2d / t)), else samples every step; 0 at the
    first inside point; the ray clipped to the bounding ball and to tmax.  Rays outside ``lit``
    (a hit facing away from the light: its own shadow) trace nothing and get 0."""
    if lit is not None:
        vis = np.zeros(len(o))
        vis[lit] = shadow_ray(o[lit], l[lit], np.asarray(tmax)[lit], c, max_iter, bailout, radius, step, softness,
                              max_steps, soft, F)
        return vis
    n = len(o)
    b = dot4(o, l)
    perp = o - b[:, None] * l
    disc = radius * radius - dot4(perp, perp)
    s = np.sqrt(np.maximum(disc, 0.0))
    t = np.maximum(-b - s, step)
    t1 = np.minimum(-b + s, tmax)
    active = (disc > 0) & (t1 > t)
    vis = np.ones(n)
    for _ in range(max_steps):
        k = np.nonzero(active)[0]
        if k.size == 0:
            break
        x = o[k] + t[k, None] * l[k]
        if F.has_de:
            d, esc = julia_distance_formula(x, c, max_iter, bailout, F)
            inside = ~esc
            if soft:
                vis[k] = np.where(esc, np.minimum(vis[k], softness * 2 * d / t[k]), vis[k])
            t[k] = t[k] + np.maximum(d, step)
        else:
            inside = julia_inside(x, c, max_iter, bailout, F)
            t[k] = t[k] + step
        vis[k[inside]] = 0.0
        active[k] = ~inside & (t[k] < t1[k])
    return np.clip(vis, 0.0, 1.0)


def ambient_occlusion(p, nw, c, max_iter, bailout, dist, strength, F: Formula = QUATERNION_SQR):
    """1 - strength * the w-weighted occlusion of five points p + h_i n (shade/light.cl)."""
    occ = np.zeros(len(p))
    wsum, w = 0.0, 1.0
    for i in range(1, 6):
        h = dist * i / 5
        x = p + h * nw
        if F.has_de:
            d, esc = julia_distance_formula(x, c, max_iter, bailout, F)
            d = np.where(esc, d, 0.0)
            occ += w * np.maximum(h - 2 * d, 0.0) / h
        else:
            occ += w * julia_inside(x, c, max_iter, bailout, F)
        wsum += w
        w *= 0.5
    return np.clip(1 - strength * occ / wsum, 0.0, 1.0)


def _orbit_start(p, c, F: Formula):
    """(q_start, step(q, live) -> f(q) + c on the live points, first index): the Julia orbit
    of p, or the kind's own (its twin's orbit_start: a Mandelbrot set's, of v with c = p; shade/light.cl ORBIT_*)."""
    kind_start = getattr(F.kind_twin, "orbit_start", None)
    if kind_start is not None:
        return kind_start(F, p)
    cc = F.ALG_C(np.asarray(c, np.float64))
    return F.ALG_IN(p).copy(), (lambda q, live: F.julia_f(q[live], cc)), 0


def orbit_iteration(p, c, max_iter, bailout, F: Formula = QUATERNION_SQR):
    """How long the orbit of p stays in the unit ball, smoothly, over max_iter: n the first
    index with |q_n| > 1, nu = n - 1 + ln|q_(n-1)| / (ln|q_(n-1)| - ln|q_n|), v = nu / max_iter;
    1 where it never leaves within max_iter (shade/light.cl orbit_value, COLOR_ITERATION).
    ``bailout`` is not used: the unit ball is the measure, not the escape."""
    q, step, n0 = _orbit_start(p, c, F)
    m2 = F.ALG_NORM2(q)
    prev = m2.copy()
    n = np.full(len(q), n0)
    live = m2 <= 1.0
    with np.errstate(all="ignore"):
        for _ in range(n0, max_iter):
            if not live.any():
                break
            prev[live] = m2[live]
            q[live] = step(q, live)
            m2[live] = F.ALG_NORM2(q[live])
            n[live] += 1
            live &= m2 <= 1.0
        lo = np.log(np.maximum(prev, np.finfo(np.float64).tiny))
        hi = np.log(np.maximum(m2, 1.0))
        frac = np.clip(-lo / np.maximum(hi - lo, np.finfo(np.float64).tiny), 0.0, 1.0)
    nu = np.where(n == n0, float(n0), n - 1 + frac)
    return np.where(live, 1.0, np.clip(nu / max_iter, 0.0, 1.0))


def orbit_trap(p, c, max_iter, bailout, trap, F: Formula = QUATERNION_SQR):
    """1 - exp(-3 min_n |q_n - trap|) over the orbit while inside the bailout (COLOR_TRAP)."""
    q, step, n0 = _orbit_start(p, c, F)
    tq = F.ALG_IN(np.asarray(trap, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    live = m2 <= b2
    best = F.ALG_NORM2(q - tq)
    with np.errstate(all="ignore"):
        for _ in range(n0, max_iter):
            if not live.any():
                break
            q[live] = step(q, live)
            m2 = F.ALG_NORM2(q)
            live &= m2 <= b2
            best = np.where(live, np.minimum(best, F.ALG_NORM2(q - tq)), best)
    return 1 - np.exp(-3 * np.sqrt(best))


def light_terms(point, normal, status, bracket, frame: Frame, march: MarchArgs, light: LightArgs, light_pos,
                F: Formula = QUATERNION_SQR):
    """shade/light.cl light_terms with the same records (``march``, ``light``:
    pipeline/plan.MarchArgs, LightArgs; ``light_pos`` the positioned light, ShadeArgs.light):
    (visibility, ambient factor, colour value, 0) per item, (1, 1, 0, 0) off hits."""
    c, max_iter, bailout, radius, eye = march.c, march.max_iter, march.bailout, march.radius, frame.position
    step, bias, softness, max_steps, trap = light.step, light.bias, light.softness, light.max_steps, light.trap
    shadow, coloring = light.shadow, light.coloring
    n = len(status)
    out = np.tile(np.array([1.0, 1.0, 0.0, 0.0]), (n, 1))
    hit = status == STATUS_HIT
    k = np.nonzero(hit)[0]
    if k.size == 0:
        return out
    p = point[k]
    nc = normal[k]
    nw = nc[:, :1] * frame.right + nc[:, 1:2] * frame.up - nc[:, 2:3] * frame.forward
    if shadow != "none":
        o = p + bias * nw
        lv = np.asarray(light_pos, np.float64) - o
        dist = np.linalg.norm(lv, axis=-1)
        # a hit facing away from the light is its own shadow, and traces none (shade/light.cl LIGHT_FACES)
        f = dot4(nw, np.asarray(light_pos, np.float64) - p) > 0
        out[k, 0] = shadow_ray(o, lv / np.maximum(dist, 1e-300)[:, None], dist, c, max_iter, bailout, radius,
                               step, softness, max_steps, shadow == "soft", F, lit=f)
    if light.ao_strength > 0:
        out[k, 1] = ambient_occlusion(p + bias * nw, nw, c, max_iter, bailout, light.ao_distance, light.ao_strength, F)
    if coloring == "iteration":
        dirs = p - np.asarray(eye, np.float64)
        dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
        out[k, 2] = orbit_iteration(p + bracket[k, None] * dirs, c, max_iter, bailout, F)
    elif coloring == "trap":
        out[k, 2] = orbit_trap(p, c, max_iter, bailout, trap, F)
    elif coloring == "w":
        out[k, 2] = np.clip(0.5 + p[:, 3] / radius, 0.0, 1.0)
    return out


def extra_visibility(point, normal, status, frame: Frame, march: MarchArgs, light: LightArgs, shade: ShadeArgs,
                     F: Formula = QUATERNION_SQR):
    """The visibility of each of shading.lights (shade/light.cl, EXTRA_SHADOWS) with the same
    records: (n, 4), column j for light j (geo, rgb as camera.extra_lights: rgb[j, 3] = 1 a
    distant light along geo[j]), 1 off hits and in unused columns."""
    c, max_iter, bailout, radius = march.c, march.max_iter, march.bailout, march.radius
    step, bias, softness, max_steps = light.step, light.bias, light.softness, light.max_steps
    soft, geo, rgb = light.extra_shadow == "soft", shade.lights_geo[:shade.n_lights], shade.lights_rgb
    n = len(status)
    out = np.ones((n, 4))
    out[:, 3] = 0.0
    k = np.nonzero(status == STATUS_HIT)[0]
    if k.size == 0:
        return out
    nc = normal[k]
    nw = nc[:, :1] * frame.right + nc[:, 1:2] * frame.up - nc[:, 2:3] * frame.forward
    o = point[k] + bias * nw
    for j in range(len(geo)):
        if rgb[j, 3] != 0:
            lv = to = np.broadcast_to(np.asarray(geo[j], np.float64), o.shape)
            dist = np.full(len(k), np.inf)
        else:
            lv = np.asarray(geo[j], np.float64) - o
            to = np.asarray(geo[j], np.float64) - point[k]
            dist = np.linalg.norm(lv, axis=-1)
        l = lv / np.maximum(np.linalg.norm(lv, axis=-1), 1e-300)[:, None]
        # facing the light (shade/light.cl LIGHT_FACES), or lit along the view where the light has
        # no direction in the rays' 3D space (shade.cl); else its own shadow
        f = (dot4(nw, to) > 0) | np.all(to_camera(to, frame) == 0, axis=-1)
        out[k, j] = shadow_ray(o, l, dist, c, max_iter, bailout, radius, step, softness, max_steps, soft, F, lit=f)
    return out


def unit_or(a, fallback):
    """a / |a| per row, ``fallback`` where a has no direction (|a|^2 is 0 or not finite):
    shade.cl's UNIT3 (common/lanes.cl)."""
    aa = np.sum(a * a, axis=-1, keepdims=True)
    ok = (aa > 0) & np.isfinite(aa)
    return np.where(ok, a / np.sqrt(np.where(ok, aa, 1.0)), fallback)


def shade(status, normal, point, frame: Frame, args: ShadeArgs, terms=None, lut=None, vis_extra=None, refl=None):
    """shade/shade.cl with the same record (``args``: pipeline/plan.ShadeArgs).  Lambert
    (light at the eye by default, Hart, Sandin & Kauffman 1989 §4) + ambient (times the sky) + Blinn-Phong, with
    the light's visibility and ambient occlusion from ``terms`` and the base colour from the
    colour table ``lut`` at terms' colour value; shading.lights (camera.extra_lights)
    likewise, their visibility from ``vis_extra``; the mirror bounce's colour ``refl``
    (shade/reflect.cl) mixed in; RGBA, linear light."""
    light_pos, color, background, light_color = args.point_light, args.color, args.background, args.light_color
    ambient, diffuse, specular, shininess = args.ambient, args.diffuse, args.specular, args.shininess
    fog, fog_start, sky, reflection = args.fog, args.fog_start, args.sky, args.reflection
    lights_geo = args.lights_geo[:args.n_lights] if args.n_lights else None
    lights_rgb = args.lights_rgb[:args.n_lights] if args.n_lights else None
    hit = status == STATUS_HIT
    rgba = np.zeros((len(status), 4))
    rgba[:, :3] = background
    if not hit.any():
        return rgba
    # the hit is the eye itself (depth 0, camera inside the set): the view axis (shade.cl)
    p = unit_or(to_camera(point[hit] - frame.position, frame), np.array([0.0, 0.0, -1.0]))
    v = -p
    # the light at the hit itself: from the eye
    l = v if light_pos is None else unit_or(to_camera(np.asarray(light_pos) - point[hit], frame), v)
    n = normal[hit]
    lam = np.maximum(dot4(n, l), 0.0)
    vis = terms[hit, 0] if terms is not None else np.ones(len(lam))
    ao = terms[hit, 1] if terms is not None else np.ones(len(lam))
    if lut is not None:
        base = lookup(lut, terms[hit, 2])
    else:
        base = np.asarray(color)[None, :]
    def lit(l, vis):
        lam = np.maximum(dot4(n, l), 0.0)
        out = base * (diffuse * vis * lam)[:, None]
        if specular > 0:
            hv = unit_or(l + v, 0.0)   # none (the light straight behind): no highlight
            spec = np.where(lam > 0, np.maximum(dot4(n, hv), 0.0) ** shininess, 0.0)
            out = out + (vis * specular * spec)[:, None]
        return out

    rgb = base * (ambient * ao)[:, None] * np.asarray(sky)[None, :] + lit(l, vis) * np.asarray(light_color)[None, :]
    for j in range(0 if lights_geo is None else len(lights_geo)):
        if lights_rgb[j, 3] != 0:
            lj = np.broadcast_to(to_camera(np.asarray(lights_geo[j])[None, :], frame), p.shape)
        else:
            lj = to_camera(np.asarray(lights_geo[j]) - point[hit], frame)
        lj = unit_or(lj, v)
        vj = vis_extra[hit, j] if vis_extra is not None else np.ones(len(lam))
        rgb = rgb + lit(lj, vj) * np.asarray(lights_rgb[j, :3])[None, :]
    if refl is not None:   # the mirror bounce (shade/reflect.cl), before depth cueing
        rgb = rgb * (1 - reflection) + refl[hit, :3] * reflection
    if fog > 0:   # depth cueing toward the background (shade.cl, -D FOG)
        t = np.linalg.norm(point[hit] - frame.position, axis=-1)   # the 4D distance, as shade.cl
        k = np.exp(-fog * np.maximum(t - fog_start, 0.0))[:, None]
        rgb = np.asarray(background)[None, :] * (1 - k) + rgb * k
    rgba[hit, :3] = rgb
    rgba[hit, 3] = 1.0
    return rgba


def reflect_rays(point, normal, status, frame: Frame, bias, radius):
    """shade/reflect.cl reflect_rays: (origins, dirs) of the mirror bounce d' = d - 2 (d . n) n
    from p + bias n for hits; a ray leaving the bounding ball elsewhere."""
    n_items = len(status)
    origins = np.tile([4.0 * radius, 0.0, 0.0, 0.0], (n_items, 1))
    dirs = np.tile([1.0, 0.0, 0.0, 0.0], (n_items, 1))
    k = np.nonzero(status == STATUS_HIT)[0]
    if k.size == 0:
        return origins, dirs
    nc = normal[k]
    nw = nc[:, :1] * frame.right + nc[:, 1:2] * frame.up - nc[:, 2:3] * frame.forward
    d = point[k] - frame.position
    dl = np.linalg.norm(d, axis=-1, keepdims=True)
    d = np.where(dl > 0, d / np.where(dl > 0, dl, 1), frame.forward)
    r = d - 2 * dot4(d, nw)[:, None] * nw
    rl = np.linalg.norm(r, axis=-1, keepdims=True)
    dirs[k] = np.where(rl > 0, r / np.where(rl > 0, rl, 1), -d)
    origins[k] = point[k] + bias * nw
    return origins, dirs


def reflect_color(status, normal, point, dirs, frame: Frame, args: ShadeArgs):
    """shade/reflect.cl reflect_color with shading's record (``args``: pipeline/plan.ShadeArgs):
    color (ambient sky + diffuse max(n . l, 0) light_color) on the reflected hits, l towards
    the light (back along the ray for the light at the eye); the background elsewhere.  RGBA
    (alpha 1 on hits)."""
    light_pos, color, background, light_color = args.point_light, args.color, args.background, args.light_color
    sky, ambient, diffuse = args.sky, args.ambient, args.diffuse
    out = np.zeros((len(status), 4))
    out[:, :3] = background
    k = np.nonzero(status == STATUS_HIT)[0]
    if k.size == 0:
        return out
    nc = normal[k]
    nw = nc[:, :1] * frame.right + nc[:, 1:2] * frame.up - nc[:, 2:3] * frame.forward
    if light_pos is None:
        l = -dirs[k]
    else:
        l = np.asarray(light_pos, np.float64) - point[k]
        ll = np.linalg.norm(l, axis=-1, keepdims=True)
        l = np.where(ll > 0, l / np.where(ll > 0, ll, 1), -dirs[k])
    lam = np.maximum(dot4(nw, l), 0.0)
    out[k, :3] = np.asarray(color) * (ambient * np.asarray(sky) + diffuse * lam[:, None] * np.asarray(light_color))
    out[k, 3] = 1.0
    return out
