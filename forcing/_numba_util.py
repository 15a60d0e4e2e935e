"""Serial and parallel builds of one numba kernel (shared with the model:
see :mod:`lagice._numba`). The forcing kernels switch to parallel builds
only from 50 000 points: their work per point is tiny."""
from __future__ import annotations

from lagice._numba import PARALLEL_MIN_SIZE as _MODEL_MIN
from lagice._numba import pick as _pick
from lagice._numba import serial_and_parallel

#: arrays shorter than this run the serial build (``LAGICE_PARALLEL_MIN_SIZE``
#: overrides it when larger)
PARALLEL_MIN_SIZE = max(50000, _MODEL_MIN)

__all__ = ["serial_and_parallel", "pick", "PARALLEL_MIN_SIZE"]


def pick(kernels, n):
    """The serial build for ``n < PARALLEL_MIN_SIZE``, else the parallel one."""
    return _pick(kernels, n, PARALLEL_MIN_SIZE)
