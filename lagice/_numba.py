"""Serial and parallel builds of one numba kernel, chosen by problem size.

A ``parallel=True`` launch costs a thread wake-up: tens of µs on an idle
machine, milliseconds when the cores are busy with other work, which
dominates for small meshes. :func:`serial_and_parallel` compiles a kernel
twice; the serial copy gets its own name and qualname, because numba's disk
cache is keyed by qualname, not by the ``parallel`` flag. :func:`pick`
chooses by size.
"""
from __future__ import annotations

import os
import types

from numba import njit

#: problems smaller than this run the serial build (environment override
#: ``LAGICE_PARALLEL_MIN_SIZE``). Measured on the project's 2-vCPU machines,
#: which share their cores with other work: the winter_basin explicit step
#: (26k elements, 145 sub-steps) ran 24 M element-sub-steps/s with serial
#: kernels and 1.7 M/s with parallel ones; the implicit compression step at
#: 7.4k elements 13.7 ms serial vs 42-56 ms parallel. Parallel kernels pay only
#: on idle multi-core machines: set LAGICE_PARALLEL_MIN_SIZE=20000 there.
PARALLEL_MIN_SIZE = int(os.environ.get("LAGICE_PARALLEL_MIN_SIZE", "200000"))


def serial_copy(py_func, **njit_kw):
    """A serial numba dispatcher of ``py_func`` (``prange`` runs as ``range``)."""
    py_func = getattr(py_func, "py_func", py_func)
    ser = types.FunctionType(py_func.__code__, py_func.__globals__, py_func.__name__ + "_serial",
                             py_func.__defaults__, py_func.__closure__)
    ser.__qualname__ = py_func.__qualname__ + "_serial"
    ser.__module__ = py_func.__module__
    ser.__doc__ = py_func.__doc__
    return njit(cache=True, **njit_kw)(ser)


def serial_and_parallel(py_func, **njit_kw):
    """``(serial, parallel)`` numba dispatchers of ``py_func``."""
    py_func = getattr(py_func, "py_func", py_func)
    return serial_copy(py_func, **njit_kw), njit(cache=True, parallel=True, **njit_kw)(py_func)


def pick(kernels, n, threshold: int | None = None):
    """The serial build for ``n`` below the threshold, else the parallel one."""
    return kernels[0] if n < (PARALLEL_MIN_SIZE if threshold is None else threshold) else kernels[1]
