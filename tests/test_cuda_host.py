"""The GPU stepper's prepared launches (:mod:`lagice.solvers.cuda_host`), without a GPU.

On a GPU, ``tests/cuda_sim_compare.py`` (case ``host_path_fast_vs_numba``) checks that a
run with prepared launches and direct copies equals numba's own calls bit for bit. Here,
where no GPU is, the bookkeeping is checked against a stand-in for numba's CUDA
dispatcher module: a dispatcher whose ``[grid, block](*args)`` converts its arguments
as numba does (``_prepare_args``) and hands them to the module's ``launch``, as
numba-cuda's ``_Kernel.launch`` hands them to ``cuda.core``'s ``launch``. What is
checked: every prepared launch passes exactly the values a fresh conversion gives,
also after the work arrays swap places, when a scalar changes its value or type, and
when an argument changes its dtype; a numba that does not pass through a known launch
call turns prepared launches off after one launch, which ran once.
"""
from __future__ import annotations

import ctypes
import sys
import types

import numpy as np
import pytest
from numba import typeof

from lagice.solvers.cuda_host import HostPath

MOD = "lagice_test_fake_dispatcher"


def _prepare(ty, val, stream, retr, kernelargs):
    """numba-cuda's conversion, in small: an array as (size, itemsize, pointer, shape,
    strides), a float64 as a c_double, an integer as a c_int64."""
    if isinstance(val, np.ndarray):
        kernelargs.extend([0, 0, val.size, val.itemsize, val.ctypes.data, *val.shape, *val.strides])
    elif isinstance(val, float):
        kernelargs.append(ctypes.c_double(val))
    else:
        kernelargs.append(ctypes.c_int64(val))


class _Compiled:
    def __init__(self, argtypes):
        self.argument_types = argtypes
        self._prepare_args = _prepare


def _module(with_launch=True):
    mod = types.ModuleType(MOD)
    mod.calls = []
    if with_launch:
        mod.LaunchConfig = type("LaunchConfig", (), {})

        def launch(stream, config, kern, *kernelargs):
            mod.calls.append((kern, [getattr(a, "value", a) for a in kernelargs]))

        mod.launch = launch
    sys.modules[MOD] = mod
    return mod


class _Dispatcher:
    """Compiles one overload per argument-type tuple; launches through its module's ``launch``."""

    def __init__(self, mod, name):
        self.mod, self.name, self.overloads = mod, name, {}

    def __getitem__(self, cfg):
        def call(*args):
            sig = tuple(typeof(a) for a in args)
            self.overloads.setdefault(sig, _Compiled(sig))
            kernelargs = []
            for t, v in zip(sig, args):
                _prepare(t, v, 0, [], kernelargs)
            if hasattr(self.mod, "launch"):
                self.mod.launch(0, cfg, (self.name, sig), *kernelargs)
            else:
                self.mod.calls.append(((self.name, sig), [getattr(a, "value", a) for a in kernelargs]))
        return call


_Dispatcher.__module__ = MOD


def _reference(args):
    out = []
    for v in args:
        _prepare(None, v, 0, [], out)
    return [getattr(a, "value", a) for a in out]


@pytest.fixture
def fast_path(monkeypatch):
    """A HostPath with the fast path on, the driver replaced by a stand-in (copies unused here)."""
    io = HostPath(fast=False)
    monkeypatch.setattr(io, "_drv", types.SimpleNamespace())
    monkeypatch.setattr(io, "fast", True)
    yield io
    sys.modules.pop(MOD, None)


def test_prepared_launches_pass_what_numba_would(fast_path):
    mod = _module()
    kern = _Dispatcher(mod, "k")
    a, b, c = np.zeros(5), np.ones(5), np.zeros((5, 2))
    launches = [(a, b, c, 0.5, 3), (a, b, c, 0.25, 4), (b, a, c, 0.25, 4),  # swapped work arrays
                (b, a, c, 0.125, 4), (a, b, c, 1.0, 7)]
    for args in launches:
        fast_path.launch(kern, 2, 32, args)
    assert len(mod.calls) == len(launches)
    for (_, values), args in zip(mod.calls, launches):
        assert values == _reference(args)
    assert fast_path.counts["prepared"] == 1  # one pack, converted arrays reused
    assert fast_path.prepared_launches and fast_path.note == ""


def test_a_scalar_or_dtype_change_makes_a_new_pack(fast_path):
    mod = _module()
    kern = _Dispatcher(mod, "k")
    a, b = np.zeros(4), np.zeros(4, np.float32)
    runs = [(a, 1.5), (a, 2), (b, 2), (a, 1.5)]  # float -> int scalar, float64 -> float32 array
    for args in runs:
        fast_path.launch(kern, 1, 32, args)
    sigs = [call[0][1] for call in mod.calls]
    assert sigs == [tuple(typeof(x) for x in args) for args in runs]
    for (_, values), args in zip(mod.calls, runs):
        assert values == _reference(args)
    assert fast_path.counts["prepared"] == 4


def test_unknown_launch_call_turns_prepared_launches_off_after_one_launch(fast_path):
    mod = _module(with_launch=False)
    kern = _Dispatcher(mod, "k")
    a = np.zeros(3)
    fast_path.launch(kern, 1, 32, (a, 1.0))
    assert len(mod.calls) == 1  # launched once, not again by the fallback
    assert not fast_path.prepared_launches and "no known launch call" in fast_path.note
    fast_path.launch(kern, 1, 32, (a, 2.0))  # numba's own launch from now on
    assert [v for _, v in mod.calls] == [_reference((a, 1.0)), _reference((a, 2.0))]


def test_the_switch_takes_0_or_1(monkeypatch):
    from lagice.errors import ConfigError
    from lagice.solvers.cuda_host import fast_host_wanted

    monkeypatch.delenv("LAGICE_CUDA_FAST_HOST", raising=False)
    assert fast_host_wanted()
    monkeypatch.setenv("LAGICE_CUDA_FAST_HOST", "0")
    assert not fast_host_wanted()
    monkeypatch.setenv("LAGICE_CUDA_FAST_HOST", "yes")
    with pytest.raises(ConfigError, match="LAGICE_CUDA_FAST_HOST = 'yes': expected 0 or 1"):
        fast_host_wanted()
