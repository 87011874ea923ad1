"""The status codes and guard flags the kernels write, read from their one definition,
kernels/common/codes.cl (``#define NAME value`` lines), so that the host, the float64 reference
and the kernels cannot disagree."""
from __future__ import annotations

import re

from pyjulia4d.resources import kernel_dir

_DEFINE = re.compile(r"^#define\s+([A-Z][A-Z0-9_]*)\s+(\d+)\b", re.M)


def read_codes() -> dict[str, int]:
    """{name: value} of every integer #define in kernels/common/codes.cl."""
    return {name: int(value) for name, value in _DEFINE.findall((kernel_dir() / "common/codes.cl").read_text())}


CODES = read_codes()
STATUS_MISS = CODES["STATUS_MISS"]
STATUS_HIT = CODES["STATUS_HIT"]
STATUS_CAPPED = CODES["STATUS_CAPPED"]
GUARD_NORMAL_FALLBACK = CODES["GUARD_NORMAL_FALLBACK"]
GUARD_JACOBIAN_TINY = CODES["GUARD_JACOBIAN_TINY"]
GUARD_ULP_STEP = CODES["GUARD_ULP_STEP"]
GUARD_SHELL_MISS = CODES["GUARD_SHELL_MISS"]
FLAG_CUT_FACE = CODES["FLAG_CUT_FACE"]
