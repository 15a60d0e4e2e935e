"""Host-side cost of the GPU stepper (issue 15): direct driver copies and prepared launches.

On ``winter_basin`` (26k elements) the GPU's own work is a small part of an outer step:
most of the time is Python run by numba's CUDA layer around each copy and launch
(``docs/gpu.md``, "Where the host time goes"). Two of its costs do not depend on what
is copied or launched:

* **copies.** ``DeviceNDArray.copy_to_device`` / ``copy_to_host`` check the context,
  build views of both arrays and test their contiguity before the one driver call.
  The stepper's arrays are whole, C-contiguous and of matching dtype and size (it
  allocates them), so :meth:`HostPath.h2d` and :meth:`HostPath.d2h` call the driver's
  ``cuMemcpyHtoD`` / ``cuMemcpyDtoH`` directly (synchronous, as numba's own copies
  on the default stream).
* **launches.** A launch converts every argument to its ctypes form (about 7 values
  per array). The stepper launches the same kernels on the same device arrays at
  every step, so :meth:`HostPath.launch` keeps the converted form of each array
  argument as long as the same array object is passed at that position, and converts
  only the scalars and the arrays that changed. The kernel, its compiled code and the
  argument values are the ones numba's own launch would use: results are bit for bit
  the same (``tests/cuda_sim_compare.py``, case ``host_path_fast_vs_numba`` on a GPU).

Where anything this relies on is missing (numba's CUDA simulator, which has no driver;
a numba-cuda version without these internals), :class:`HostPath` uses numba's public
calls, with a note in :attr:`HostPath.note`. ``LAGICE_CUDA_FAST_HOST=0`` turns the fast
path off (for measurements). Every copy and launch is counted (:attr:`HostPath.counts`).
"""
from __future__ import annotations

import os
import threading

import numpy as np
from numba import typeof

#: held while a first launch has numba's launch function replaced by a recorder (that
#: function is a module global: two threads must not swap it at the same time)
_PATCH_LOCK = threading.Lock()


def fast_host_wanted() -> bool:
    """``LAGICE_CUDA_FAST_HOST`` (default 1): 0 uses numba's public copies and launches."""
    v = os.environ.get("LAGICE_CUDA_FAST_HOST", "1").strip()
    if v not in ("0", "1"):
        from ..errors import ConfigError

        raise ConfigError(f"LAGICE_CUDA_FAST_HOST = {v!r}: expected 0 or 1")
    return v == "1"


class HostPath:
    """Copies and launches of one :class:`~lagice.solvers.cuda_explicit.CudaExplicitSolver`.

    Args:
        fast: use the driver directly where possible (the stepper passes
            :func:`fast_host_wanted` and not the simulator).
    """

    def __init__(self, fast: bool):
        self.note = ""
        self._drv = None
        self._launcher = None  # False once prepared launches are found unsupported
        if fast:
            try:
                from numba.cuda.cudadrv import driver

                for name in ("host_to_device", "device_to_host"):
                    getattr(driver, name)
                self._drv = driver
            except Exception as exc:  # noqa: BLE001 - any import/attribute failure: numba's public path
                self.note = f"fast host path unavailable ({type(exc).__name__}: {exc})"
        self.fast = self._drv is not None
        self._packs = {}  # (kernel, griddim, blockdim) -> prepared argument packs
        self.counts = {"uploads": 0, "downloads": 0, "launches": 0, "prepared": 0}

    @property
    def prepared_launches(self) -> bool:
        """True while launches go through prepared arguments (False after a fallback)."""
        return self.fast and self._launcher is not False

    def clear(self) -> None:
        """Forget prepared arguments (the device arrays they point to are about to go)."""
        self._packs = {}

    # -- copies ------------------------------------------------------------------------
    def h2d(self, dev, host: np.ndarray) -> None:
        """Copy the whole host array ``host`` (C-contiguous, ``dev``'s dtype and size) to ``dev``."""
        self.counts["uploads"] += 1
        if self.fast and host.flags.c_contiguous and host.dtype == dev.dtype and host.size == dev.size:
            if host.nbytes:
                self._drv.host_to_device(dev, host, host.nbytes)
            return
        dev.copy_to_device(host)

    def d2h(self, dev) -> np.ndarray:
        """A new host array with the whole of ``dev`` (waits for the device's queued work)."""
        self.counts["downloads"] += 1
        if self.fast:
            out = np.empty(dev.shape, dev.dtype)
            if out.nbytes:
                self._drv.device_to_host(out, dev, out.nbytes)
            return out
        return dev.copy_to_host()

    # -- launches ----------------------------------------------------------------------
    def launch(self, kernel, griddim: int, blockdim: int, args: tuple) -> None:
        """``kernel[griddim, blockdim](*args)``, with the array arguments' converted form
        reused while the same array objects are passed."""
        self.counts["launches"] += 1
        if self.prepared_launches:
            try:
                self._fast_launch(kernel, griddim, blockdim, args)
                return
            except _Unsupported as exc:
                self._launcher = False
                self._packs = {}
                self.note = f"prepared launches unavailable ({exc}); numba's own launch is used"
                if exc.launched:
                    return
        kernel[griddim, blockdim](*args)

    def _fast_launch(self, kernel, griddim, blockdim, args) -> None:
        key = (id(kernel), griddim, blockdim)
        pack = self._packs.get(key)
        if pack is None or pack["kernel"] is not kernel or len(pack["args"]) != len(args):
            self._packs[key] = self._first_launch(kernel, griddim, blockdim, args)
            return
        prepare, types = pack["prepare"], pack["types"]
        held, parts, pytypes = pack["args"], pack["parts"], pack["pytypes"]
        kernelargs = []
        for i, v in enumerate(args):
            if held[i] is None:  # a scalar: converted at every launch, of the type compiled for
                if type(v) is not pytypes[i]:
                    self._packs[key] = self._first_launch(kernel, griddim, blockdim, args)
                    return
                prepare(types[i], v, 0, [], kernelargs)
                continue
            if held[i] is not v:  # another device array at this position (the swapped work arrays)
                if typeof(v) != types[i]:
                    self._packs[key] = self._first_launch(kernel, griddim, blockdim, args)
                    return
                part = []
                prepare(types[i], v, 0, [], part)
                held[i], parts[i] = v, part
            kernelargs.extend(parts[i])
        pack["launch"](*pack["head"], *kernelargs, **pack["kw"])

    def _first_launch(self, kernel, griddim, blockdim, args) -> dict:
        """Launch through numba, recording what it hands the launch call (``cuda.core``'s
        ``launch`` in recent numba-cuda, the driver's ``launch_kernel`` before); build the
        pack from the compiled kernel and check that it converts the arguments to the
        same values."""
        import sys

        with _PATCH_LOCK:  # numba's launch functions are module globals: one first launch at a time
            seen = {}
            patched = []
            mod = sys.modules.get(type(kernel).__module__)
            core_launch = getattr(mod, "launch", None) if mod is not None and hasattr(mod, "LaunchConfig") else None
            if callable(core_launch):
                def record_core(stream, config, kern, *kernelargs):
                    seen.update(launch=core_launch, head=(stream, config, kern), kw={},
                                values=[_value(a) for a in kernelargs])
                    return core_launch(stream, config, kern, *kernelargs)

                patched.append((mod, "launch", core_launch, record_core))
            drv_launch = getattr(self._drv, "launch_kernel", None)
            if callable(drv_launch):
                def record_drv(handle, gx, gy, gz, bx, by, bz, sharedmem, stream, kernelargs, cooperative=False):
                    if sharedmem == 0:
                        seen.update(launch=_driver_launch(drv_launch), head=(handle, gx, gy, gz, bx, by, bz, 0, stream),
                                    kw={"cooperative": cooperative}, values=[_value(a) for a in kernelargs])
                    return drv_launch(handle, gx, gy, gz, bx, by, bz, sharedmem, stream, kernelargs,
                                      cooperative=cooperative)

                patched.append((self._drv, "launch_kernel", drv_launch, record_drv))
            for owner, name, _, rec in patched:
                setattr(owner, name, rec)
            try:
                kernel[griddim, blockdim](*args)
            finally:
                for owner, name, orig, _ in patched:
                    setattr(owner, name, orig)
        # from here on the kernel has run: any failure only turns the fast path off
        if not seen:
            raise _Unsupported("no known launch call (cuda.core's launch, the driver's launch_kernel) was seen",
                               launched=True)
        try:
            compiled = kernel.overloads[tuple(typeof(a) for a in args)]
            types = compiled.argument_types
            prepare = compiled._prepare_args
            held, parts, values = [], [], []
            for t, v in zip(types, args):
                part, retr = [], []
                prepare(t, v, 0, retr, part)
                if retr:
                    raise _Unsupported("an argument is a host array (numba would copy it each launch)")
                is_scalar = isinstance(v, (int, float, np.number))
                held.append(None if is_scalar else v)
                parts.append(None if is_scalar else part)
                values.extend(_value(a) for a in part)
        except _Unsupported as exc:
            raise _Unsupported(str(exc), launched=True) from exc
        except Exception as exc:  # noqa: BLE001 - internals missing or changed: numba's own launch
            raise _Unsupported(f"{type(exc).__name__}: {exc}", launched=True) from exc
        if seen["values"] != values:
            raise _Unsupported("the arguments numba passed differ from the prepared ones", launched=True)
        self.counts["prepared"] += 1
        return {"kernel": kernel, "launch": seen["launch"], "head": seen["head"], "kw": seen["kw"],
                "types": types, "prepare": prepare, "args": held, "parts": parts,
                "pytypes": [type(v) for v in args]}


def _driver_launch(fn):
    """The driver's ``launch_kernel(..., kernelargs, cooperative=...)`` taking the kernel
    arguments spread, as ``cuda.core``'s ``launch`` does."""
    def call(*head_and_args, cooperative=False):
        return fn(*head_and_args[:9], list(head_and_args[9:]), cooperative=cooperative)
    return call


def _value(c):
    """The value a ctypes argument holds (what the launch reads); plain ints as they are."""
    return getattr(c, "value", c)


class _Unsupported(Exception):
    """This numba-cuda does not have what the prepared launch relies on (``launched``:
    the kernel already ran through numba's own launch)."""

    def __init__(self, msg, launched=False):
        super().__init__(msg)
        self.launched = launched
