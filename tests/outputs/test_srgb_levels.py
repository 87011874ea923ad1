"""colormap.levels_u8 (tables) against levels_u8_reference (the transfer function value by
value): the same 8-bit levels bit for bit, at every float32 around each of the 255 steps
and over a random draw of all values, special ones included.  The reference is the
definition (IEC 61966-2-1's sRGB curve in float64, rounded half to even), so any difference
is an error of the tables; no tolerance."""
from __future__ import annotations

import numpy as np
import pytest

from pyjulia4d.pipeline.colormap import (INF_BITS, ONE_BITS, TABLES_FROM, U8_SHIFT, levels_u8_reference, u8_tables)
from pyjulia4d.pipeline.colormap import levels_u8 as levels_any


def levels_u8(x, srgb=True):
    """levels_u8 from its tables, however few the values"""
    return levels_any(x, srgb, total=TABLES_FROM)


SPECIAL = np.array([np.nan, -np.nan, np.inf, -np.inf, 0.0, -0.0, 1.0, 0.5, 0.0031308, 0.04045,
                    np.nextafter(np.float32(1), np.float32(2)), np.nextafter(np.float32(0), np.float32(1)),
                    -np.nextafter(np.float32(0), np.float32(1)), 3e38, -3e38, 1e-30, 254.5 / 255, 0.5 / 255],
                   np.float32)


def test_levels_match_the_transfer_function_at_every_step() -> None:
    srgb = True
    assert u8_tables() is not None   # the tables hold on this platform (else the reference is used)
    level, thr = u8_tables()
    steps = thr[thr != 0xFFFFFFFF].astype(np.int64)
    # the level climbs 0..255 one step at a time from bucket to bucket; each step lies inside
    # a bucket (its threshold in the table) or exactly at the next bucket's start
    rise = np.diff(level.astype(int))
    assert level[0] == 0 and level[-1] == 255 and rise.min() >= 0 and rise.max() == 1
    assert len(steps) <= int(np.count_nonzero(rise)) == 255
    near = (steps[:, None] + np.arange(-2048, 2048)[None, :]).ravel()
    near = near[(near >= 0) & (near <= ONE_BITS)].astype(np.uint32).view(np.float32)
    np.testing.assert_array_equal(levels_u8(near, srgb), levels_u8_reference(near, srgb))
    starts = (np.arange(len(level), dtype=np.int64) << U8_SHIFT)
    edges = (starts[:, None] + np.arange(-2, 3)[None, :]).ravel()
    edges = edges[(edges >= 0) & (edges <= ONE_BITS)].astype(np.uint32).view(np.float32)
    np.testing.assert_array_equal(levels_u8(edges, srgb), levels_u8_reference(edges, srgb))


@pytest.mark.parametrize("srgb", [True, False])
def test_levels_match_over_all_values(srgb: bool) -> None:
    rng = np.random.default_rng(7)
    bits = rng.integers(0, 1 << 32, 2_000_000, dtype=np.uint64).astype(np.uint32)   # any float32, NaNs too
    unit = rng.integers(0, ONE_BITS + 1, 2_000_000, dtype=np.uint64).astype(np.uint32)
    x = np.concatenate([bits.view(np.float32), unit.view(np.float32), rng.random(1_000_000, np.float32), SPECIAL])
    got = levels_u8(x, srgb)
    np.testing.assert_array_equal(got, levels_u8_reference(x, srgb))
    assert got[np.isnan(x)].max() == 0 and got[x <= 0].max() == 0 and got[x >= 1].min() == 255
    assert (np.asarray(INF_BITS, np.uint32).view(np.float32) == np.inf)


def test_levels_keep_shape_and_take_any_layout() -> None:
    """An image's colour as the render keeps it (planes seen as (H, W, 3)), float64 input."""
    rng = np.random.default_rng(3)
    planes = rng.random((3, 17, 23), np.float32)
    color = planes.transpose(1, 2, 0)
    got = levels_u8(color)
    assert got.shape == (17, 23, 3) and got.dtype == np.uint8
    np.testing.assert_array_equal(got, levels_u8_reference(color))
    x64 = rng.random((5, 7)) * 1.2 - 0.1
    np.testing.assert_array_equal(levels_u8(x64, False), levels_u8_reference(x64, False))
    for x in (np.float32(0.5), 0.25, np.array(0.75), [0.1, 0.7], np.array([[1, 2], [3, 4]]), np.array([True, False])):
        got, want = levels_u8(x), levels_u8_reference(x)
        assert got.shape == want.shape and got.dtype == np.uint8
        np.testing.assert_array_equal(got, want)


def test_few_values_take_the_reference_until_the_tables_are_built() -> None:
    """Below TABLES_FROM values in all, levels come from the reference (building the tables
    costs more than converting them); the same levels either way."""
    import pyjulia4d.pipeline.colormap as cm

    x = np.linspace(-0.1, 1.1, 1001, dtype=np.float32)
    cm.u8_tables.cache_clear()
    np.testing.assert_array_equal(cm.levels_u8(x), levels_u8_reference(x))
    assert cm.u8_tables.cache_info().currsize == 0
    np.testing.assert_array_equal(cm.levels_u8(x, total=TABLES_FROM), levels_u8_reference(x))
    assert cm.u8_tables.cache_info().currsize == 1
