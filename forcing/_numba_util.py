"""Serial and parallel builds of one numba kernel.

A ``parallel=True`` launch costs a thread wake-up (tens of µs, milliseconds
when the cores are busy with other work), which dominates for small arrays.
:func:`serial_and_parallel` compiles a kernel twice (both cached on disk,
under distinct names) and :func:`pick` chooses by problem size.
"""
from __future__ import annotations

import os
import types

from numba import njit

#: arrays shorter than this run the serial build (environment override:
#: ``LAGICE_PARALLEL_MIN_SIZE``; a huge value forces serial kernels, useful
#: on shared or oversubscribed machines where a parallel launch can cost ms)
PARALLEL_MIN_SIZE = int(os.environ.get("LAGICE_PARALLEL_MIN_SIZE", "50000"))


def serial_and_parallel(py_func):
    """``(serial, parallel)`` numba dispatchers of ``py_func`` (``prange`` runs
    as ``range`` in the serial one)."""
    ser = types.FunctionType(py_func.__code__, py_func.__globals__, py_func.__name__ + "_serial",
                             py_func.__defaults__, py_func.__closure__)
    ser.__qualname__ = py_func.__qualname__ + "_serial"
    ser.__module__ = py_func.__module__
    ser.__doc__ = py_func.__doc__
    return njit(cache=True)(ser), njit(cache=True, parallel=True)(py_func)


def pick(kernels, n):
    """The serial build for ``n < PARALLEL_MIN_SIZE``, else the parallel one."""
    return kernels[0] if n < PARALLEL_MIN_SIZE else kernels[1]
