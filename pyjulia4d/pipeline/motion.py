"""Motion blur: a frame as the mean of its renders at moments spread over the shutter.

An animation with ``animation.shutter`` > 0 renders frame n at ``motion_samples`` moments
t_k = n + shutter ((k + 1/2) / K - 1/2) (keyframes.Animation.moments: the scene of each is
interpolated from the keyframes at that fractional time, every keyed key moving) and keeps
their mean, as a film exposed over the shutter records it - the accumulation buffer of
Haeberli & Akeley, "The accumulation buffer: hardware support for high-quality rendering",
1990, §4.  Colour and alpha are averaged; the colour of each is a c + (1 - a) B, so the mean
is again the mean alpha's blend over the background, and straight alpha takes it out as for
any picture.  Depth, normals, positions and the error statements are the middle moment's
(a blurred depth would be no depth at all).  A path-traced frame's noise is that of the mean
of K independent estimates: variance sum_k var_k / K^2, paths summed.
"""
from __future__ import annotations

import dataclasses

import numpy as np


def blend(parts: list, shutter: float) -> object:
    """The RenderResults of one frame's moments, in time order, as one (module docstring)."""
    k = len(parts)
    mid = parts[k // 2]
    out = dataclasses.replace(mid)
    if all(p.color is not None for p in parts):
        out.color = np.mean([np.asarray(p.color, np.float64) for p in parts], axis=0).astype(np.float32)
    if all(p.alpha is not None for p in parts):
        out.alpha = np.mean([np.asarray(p.alpha, np.float64) for p in parts], axis=0).astype(np.float32)
    backs = [p.backdrop for p in parts if p.backdrop is not None]
    if len(backs) == k:
        out.backdrop = np.mean(backs, axis=0).astype(np.float32)
    if all(p.film is not None for p in parts):
        var = np.sum([np.asarray(p.film.variance, np.float64) for p in parts], axis=0) / k ** 2
        noise = np.sqrt(np.sum([np.asarray(p.film.noise, np.float64) ** 2 for p in parts], axis=0)) / k
        out.film = dataclasses.replace(mid.film, variance=var.astype(np.float32), noise=noise.astype(np.float32),
                                       paths=np.sum([p.film.paths for p in parts], axis=0).astype(np.int32))
    out.seconds = sum(p.seconds for p in parts)
    out.kernel_seconds = sum(p.kernel_seconds for p in parts)
    out.motion_blur = f"{k} moments over {shutter:g} of a frame"
    return out
