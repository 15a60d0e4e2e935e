"""Serial and parallel builds of one numba kernel, chosen by problem size.

A ``parallel=True`` launch costs a thread wake-up: tens of µs on an idle
machine, milliseconds when the cores are busy with other work, which
dominates for small meshes. :func:`serial_and_parallel` compiles a kernel
twice; the serial copy gets its own name and qualname, because numba's disk
cache is keyed by qualname, not by the ``parallel`` flag. :func:`pick`
chooses by size.
"""
from __future__ import annotations

import logging
import math
import os
import time
import types

import numba
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


def specialised_copy(py_func, suffix: str, constants: dict, parallel: bool = False, **njit_kw):
    """A numba dispatcher of ``py_func`` in which the module globals named in ``constants``
    take the given values (numba freezes globals at compile time, so a branch on such a
    constant is removed, and a global kernel can be swapped for another). The copy gets
    ``suffix`` on its name and qualname (numba's disk cache is keyed by qualname); its
    globals are a snapshot taken now, so make copies after every name it uses exists."""
    py_func = getattr(py_func, "py_func", py_func)
    missing = [k for k in constants if k not in py_func.__globals__]
    if missing:
        raise KeyError(f"{py_func.__qualname__}: no module global {missing}")
    glob = {**py_func.__globals__, **constants}
    f = types.FunctionType(py_func.__code__, glob, py_func.__name__ + suffix, py_func.__defaults__,
                           py_func.__closure__)
    f.__qualname__ = py_func.__qualname__ + suffix
    f.__module__ = py_func.__module__
    f.__doc__ = py_func.__doc__
    return njit(cache=True, parallel=parallel, **njit_kw)(f)


def serial_and_parallel(py_func, **njit_kw):
    """``(serial, parallel)`` numba dispatchers of ``py_func``."""
    py_func = getattr(py_func, "py_func", py_func)
    return serial_copy(py_func, **njit_kw), njit(cache=True, parallel=True, **njit_kw)(py_func)


def pick(kernels, n, threshold: int | None = None):
    """The serial build for ``n`` below the threshold, else the parallel one."""
    return kernels[0] if n < (PARALLEL_MIN_SIZE if threshold is None else threshold) else kernels[1]


#: below this many elements ``parallel = "auto"`` runs the serial kernels without
#: measuring (environment override ``LAGICE_AUTOTUNE_MIN_SIZE``): at 2000 elements
#: a sub-step of the explicit kernels takes ~50 µs serial, the order of one
#: fork/join of the parallel build on an idle machine (measured on the project's
#: 2-vCPU VM, docs/benchmarks.md), so threads cannot pay there.
AUTOTUNE_MIN_SIZE = int(os.environ.get("LAGICE_AUTOTUNE_MIN_SIZE", "2000"))

#: the parallel build must beat the serial one by this factor to be chosen (a
#: margin against timing noise on a shared machine)
AUTOTUNE_MARGIN = 1.05


def autotune(trial, n_elements: int, *, max_threads: int | None = None, repeats: int = 5,
             min_size: int | None = None, what: str = "kernels") -> dict:
    """Choose serial or parallel kernel builds and the thread count by measurement.

    ``trial(parallel: bool) -> None`` runs a fixed amount of the real work (the
    caller's kernels on copies of its arrays). Each candidate, serial (1 thread)
    and parallel with 2..``max_threads`` numba threads (default: numba's current
    thread count, ``numba.get_num_threads()``: ``NUMBA_NUM_THREADS`` or what
    ``numba.set_num_threads`` limited it to), is run once to warm up (loads the compiled kernels), then timed
    ``repeats`` times, the candidates interleaved round by round; the best time of each
    counts. The parallel build is chosen only when it is :data:`AUTOTUNE_MARGIN` faster than the serial one. Below
    ``min_size`` elements (default :data:`AUTOTUNE_MIN_SIZE`) the serial build is
    chosen without measuring.

    Leaves numba's thread count at the chosen value (for a parallel choice) and
    returns ``{"parallel", "threads", "method", "timings_ms", "n_elements"}``; the
    choice is logged on the ``lagice`` logger (the run log).
    """
    n_max = numba.get_num_threads() if max_threads is None else int(max_threads)
    n_max = max(1, min(n_max, numba.config.NUMBA_NUM_THREADS))
    min_size = AUTOTUNE_MIN_SIZE if min_size is None else int(min_size)
    out = {"n_elements": int(n_elements), "timings_ms": {}}
    if n_elements < min_size or n_max < 2:
        why = (f"below {min_size} elements" if n_elements < min_size else "one numba thread available")
        out.update(parallel=False, threads=1, method=f"rule: {why}")
    else:
        before = numba.get_num_threads()
        cands = [(False, 1)] + [(True, t) for t in range(2, n_max + 1)]
        best = {}
        try:
            for par, t in cands:  # warm-up: loads (or compiles) each build
                if par:
                    numba.set_num_threads(t)
                trial(par)
            # candidates interleaved, round after round: a disturbance of a few ms (another
            # process, the hypervisor) then hits every candidate alike instead of one
            for _ in range(max(1, int(repeats))):
                for par, t in cands:
                    if par:
                        numba.set_num_threads(t)
                    t0 = time.perf_counter()
                    trial(par)
                    dt = time.perf_counter() - t0
                    best[(par, t)] = min(best.get((par, t), math.inf), dt)
        finally:
            numba.set_num_threads(before)
        t_ser = best[(False, 1)]
        (par, t), t_best = min(((k, v) for k, v in best.items() if k[0]), key=lambda kv: kv[1])
        if t_best * AUTOTUNE_MARGIN >= t_ser:
            par, t = False, 1
        out.update(parallel=par, threads=t, method="measured",
                   timings_ms={("serial" if not p else f"parallel_{n}"): 1e3 * v for (p, n), v in best.items()})
    if out["parallel"]:
        numba.set_num_threads(out["threads"])
    tm = ", ".join(f"{k} {v:.2f} ms" for k, v in out["timings_ms"].items())
    logging.getLogger("lagice").info(
        f"{what}: {'parallel on ' + str(out['threads']) + ' threads' if out['parallel'] else 'serial'} "
        f"for {n_elements} elements ({out['method']}{'; ' + tm if tm else ''})")
    return out
