"""Compile every kernel of ``lagice.solvers.cuda_kernels`` to PTX for sm_90
(H100) with NVVM, without a GPU or a driver; prints one JSON object.

The CUDA simulator runs kernels as Python, so it cannot tell whether numba
can compile them for a device. This check can: it found that numba 0.68's
CUDA target cannot compile the builtin ``min``/``max``, which the simulator
ran happily. Run by ``tests/test_cuda_explicit.py`` in a subprocess (no
simulator); needs NVVM and libdevice (a CUDA toolkit, e.g. /usr/local/cuda, or
``CUDA_HOME``), else it reports ``{"nvvm": false}`` and the test skips.
Signatures are those the solver launches with (int32 indices, float64 data).

    python tests/cuda_ptx_check.py [OUT_DIR]   # also writes OUT_DIR/<kernel>.ptx
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numba.cuda.dispatcher as _dispatcher
from numba import config, cuda
from numba import types as T

CC = (9, 0)


class _NoDevice:
    """Device functions ask the current device for its compute capability when
    they compile; without a driver, answer the target's."""

    compute_capability = CC


def signatures():
    f8, i8 = T.float64, T.int64
    A1, A2, A3 = (T.Array(f8, k, "C") for k in (1, 2, 3))
    I1, I2 = T.Array(T.int32, 1, "C"), T.Array(T.int32, 2, "C")
    B1, B2 = T.Array(T.int8, 1, "C"), T.Array(T.int8, 2, "C")
    C1 = T.Array(i8, 1, "C")
    node = (A2, A2, A2, I1, I1, A1, A1, A1, A2, A1, A2, f8, f8, A1, B2, A2, A2)
    # ... e_dt, gamma, then pmax and use_pmax (neXtSIM's compressive term), and the optional terms
    # keep_mean (int), theta and dilat (float; 0: off)
    mat = (A1,) * 8 + (A1, i8, i8, f8, f8)
    consts = (f8,) * 9
    return {
        "substeps_cooperative": (i8, f8, *node, I2, A2, A2, A1, *mat, *consts, B1, A2, A2, C1, A1),
        "node_substep_kernel": (f8, *node),
        "element_substep_kernel": (f8, I2, A2, A2, A2, A2, A1, *mat, *consts, B1, C1),
        "finish_nodes_kernel": (i8, A2, A2, A2, C1, A1),
        "finish_elements_kernel": (I2, A2, A2, A2, A2, B1, A2, A1, C1),
        "geometry_kernel": (A2, I2, A2, A2, A1, A1, f8, A1, C1),
        "prepare_elements_kernel": (A1, A2, A1, A1, A1, f8, f8, f8, f8, f8, f8, A1, A2, A1, A1, A1, A1, A1, B1, A1),
        "finish_moduli_kernel": (A1, A1, f8),
        "max_pressure_kernel": (A1, A1, f8, f8, A1),
        "prepare_nodes_kernel": (I1, I1, B1, A1, A1, A2, A2, f8, f8, A2, i8, f8, f8, f8, A2, A2, A2, A1, A2,
                                 A1, A1, A1, A1),
        "scatter_prescribed_kernel": (I1, A1, A1, A2, A2),
        "fill_kernel": (A1, f8),
        "fill_pair_kernel": (A2, f8, f8),
        "blend_records_kernel": (A3, A3, f8, A3),
        "record_field_kernel": (A2, A1, A1, i8, i8, i8, A3, A3, f8, i8, A2, C1, i8, i8),
    }


def main():
    out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else None
    if config.ENABLE_CUDASIM:
        json.dump({"nvvm": False, "reason": "the simulator is enabled"}, sys.stdout)
        return
    try:
        from numba.cuda.cudadrv import nvvm

        nvvm.NVVM()
    except Exception as exc:  # noqa: BLE001 - no NVVM means nothing to check
        json.dump({"nvvm": False, "reason": f"{type(exc).__name__}: {exc}"}, sys.stdout)
        return
    from lagice.solvers import cuda_kernels as K

    _dispatcher.get_current_device = lambda: _NoDevice()
    report = {"nvvm": True, "nvvm_version": list(nvvm.NVVM().get_version()), "cc": list(CC), "kernels": {}}
    sigs = signatures()
    kernels = {name: getattr(K, name) for name in sigs}
    # the copies with the optional rheology terms (a run with any of them launches these)
    for name, kern in K.optional_kernels().items():
        if name in sigs:
            kernels[f"optional:{name}"] = kern
    for name, kern in kernels.items():
        sig = sigs[name.removeprefix("optional:")]
        try:
            ptx, _ = cuda.compile_ptx(kern.py_func, sig, cc=CC)
        except Exception as exc:  # noqa: BLE001 - reported per kernel
            report["kernels"][name] = {"ok": False, "error": f"{type(exc).__name__}: {str(exc)[:400]}"}
            continue
        report["kernels"][name] = {"ok": True, "grid_sync": "cudaCGGetIntrinsicHandle" in ptx}
        report["kernels"][name].update(assemble(name, ptx, out_dir))
    json.dump(report, sys.stdout)


def _tool(name):
    """A CUDA toolkit binary: on PATH, under CUDA_HOME, or /usr/local/cuda."""
    import os
    import shutil

    for cand in (shutil.which(name), Path(os.environ.get("CUDA_HOME", "/nonexistent")) / "bin" / name,
                 Path("/usr/local/cuda/bin") / name):
        if cand and Path(cand).is_file():
            return str(cand)
    return None


def _cudadevrt(ptxas):
    """libcudadevrt.a of the toolkit: next to ptxas, under CUDA_HOME or /usr/local/cuda."""
    import os

    roots = [Path(ptxas).resolve().parent.parent, Path(os.environ.get("CUDA_HOME", "/nonexistent")),
             Path("/usr/local/cuda")]
    for root in roots:
        for lib in ("lib", "lib64", "targets/x86_64-linux/lib"):
            if (root / lib / "libcudadevrt.a").is_file():
                return root / lib / "libcudadevrt.a"
    return None


def assemble(name, ptx, out_dir):
    """With ptxas: assemble for sm_90 (registers, spills); with nvlink and
    libcudadevrt: link the grid-sync kernel as the driver does at load time."""
    import re
    import subprocess
    import tempfile

    ptxas = _tool("ptxas")
    if ptxas is None:
        return {}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(out_dir) if out_dir is not None else Path(tmp)
        d.mkdir(parents=True, exist_ok=True)
        src, obj = d / f"{name}.ptx", d / f"{name}.cubin"
        src.write_text(ptx)
        r = subprocess.run([ptxas, f"-arch=sm_{CC[0]}{CC[1]}", "-c", "-v", "-o", str(obj), str(src)],
                           capture_output=True, text=True, check=False)
        out = {"ptxas_ok": r.returncode == 0}
        if r.returncode:
            out["ptxas_error"] = r.stderr[-400:]
            return out
        regs = re.findall(r"Used (\d+) registers", r.stderr)
        spills = re.findall(r"(\d+) bytes spill stores", r.stderr)
        out["registers"] = int(regs[-1]) if regs else None
        out["spill_bytes"] = sum(int(x) for x in spills)
        nvlink = _tool("nvlink")
        devrt = _cudadevrt(ptxas)
        if "cudaCGGetIntrinsicHandle" in ptx and nvlink and devrt is not None:
            r = subprocess.run([nvlink, f"-arch=sm_{CC[0]}{CC[1]}", "-o", str(d / f"{name}_linked.cubin"),
                                str(obj), str(devrt)], capture_output=True, text=True, check=False)
            out["linked_with_cudadevrt"] = r.returncode == 0
            if r.returncode:
                out["nvlink_error"] = r.stderr[-400:]
        return out


if __name__ == "__main__":
    main()
