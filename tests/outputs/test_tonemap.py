"""image.exposure and image.tonemap (pipeline/tonemap.py): what the picture files get, and
what they never touch (an EXR's linear values, the default look)."""
from __future__ import annotations

import numpy as np
import pytest

from pyjulia4d.pipeline.tonemap import agx, aces, display


def ramp() -> np.ndarray:
    """Grey from 2^-10 to 2^8, a row of (1, 1, 3) pixels per stop."""
    v = 2.0 ** np.linspace(-10, 8, 73)
    return np.repeat(v[:, None, None], 3, axis=2).astype(np.float32)


def test_default_is_the_picture_itself() -> None:
    c = np.random.default_rng(0).random((4, 5, 3)).astype(np.float32)
    assert display(c) is c


@pytest.mark.parametrize("curve", [agx, aces], ids=["agx", "aces"])
def test_curves_are_monotone_bounded_and_keep_grey(curve) -> None:
    out = curve(ramp())[:, 0, :]
    assert np.all(out >= 0) and np.all(out <= 1)
    assert np.all(np.diff(out[:, 1]) >= -1e-6)                 # brighter in, never darker out
    assert out[-1, 1] > 0.9 and out[0, 1] < 0.01               # highlights roll off to white, shadows to black
    assert np.allclose(out[:, 0], out[:, 1], atol=2e-3) and np.allclose(out[:, 2], out[:, 1], atol=2e-3)


def test_middle_grey_lands_mid_scale() -> None:
    """Scene-linear 0.18 grey: about 0.1 of the display's white through the ACES 1.0 SDR
    transform (about 10 of its 100 nits), about 0.2 through AgX; both far from clamp's
    1.0 cut, which is why bright lights no longer burn out."""
    g = np.full((1, 1, 3), 0.18, np.float32)
    assert 0.07 < float(aces(g)[0, 0, 1]) < 0.14
    assert 0.12 < float(agx(g)[0, 0, 1]) < 0.3


def test_exposure_is_stops_before_the_curve() -> None:
    c = np.full((1, 1, 3), 0.1, np.float32)
    assert np.allclose(display(c, 1.0, "clamp"), 0.2)
    assert np.allclose(display(c, 1.0, "agx"), agx(c * 2))


def test_agx_keeps_a_saturated_hue() -> None:
    """A bright saturated orange stays orange (red > green > blue) where clamp would flatten
    it towards yellow-white."""
    out = agx(np.array([[[8.0, 2.0, 0.3]]], np.float32))[0, 0]
    assert out[0] > out[1] > out[2]
