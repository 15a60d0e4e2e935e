"""GPU explicit Maxwell-EB time stepper (issue 15): :class:`CudaExplicitSolver`.

The same outer step as :class:`lagice.solvers.explicit.ExplicitSolver`, with
every per-element and per-node loop on an NVIDIA GPU through ``numba.cuda``
(kernels in :mod:`lagice.solvers.cuda_kernels`), the state kept on the device
between outer steps. It follows :class:`lagice.solvers.base.TimeStepper`:
``step(state, t_s, dt_s)`` advances velocity, stress and damage over
[t_s, t_s + dt_s] (the model owns the clock), :attr:`transport_velocity` is the
mean of the sub-step velocities, :attr:`last_strain_rate` its strain rate.
Design, sync rules and measured agreement with the CPU stepper: ``docs/gpu.md``.

What runs where, per outer step
-------------------------------
host (Python, O(boundary) or O(1) work):
  prescribed velocities at the boundary dofs (``VelocityBC`` callables),
  forcing fields that have no records (callables: evaluated at the nodes and
  copied over; constants: filled on the device once), the record bracket
  (which two records, weight ``a``) and reading a record when the bracket
  moves on, a ``heal_rate`` callable, the sub-step count and stability check.
device:
  record fields interpolated at the nodes (bilinear in space, linear in time,
  as :class:`forcing.records.RecordField`), E, λ, exp(−c*(1−A)), strengths,
  lumped mass, adjacency weights, wind force and drag coefficients, then the
  sub-step loop (node velocity + element stress/damage/healing), the sub-step
  mean velocity (transport velocity) and its strain rate, and the checks the
  NaN checker needs (non-finite counts, largest speed).

Two host↔device synchronisations per outer step read a handful of counters:
after the setup (E_max for the sub-step count; forcing points outside the
grid / non-finite) and after the sub-steps (capped, damaged and non-finite
counts, largest speed).

Launches per sub-step: none with the cooperative kernel (``launch="auto"``
where the device supports it: one launch runs all sub-steps with grid-wide
barriers); two with ``launch="launches"`` (node kernel, element kernel).

The node system (prescribed dofs from :class:`~lagice.boundary.DirichletSet`,
P1 geometry, lumped mass and adjacency weights) is the device counterpart of
:class:`lagice.fem.NodeSystem`: the prescribed dofs and the fixed flags are
built on the host from the same ``DirichletSet``, everything per element and
per node is computed on the device.
"""
from __future__ import annotations

import functools
import math
import time
import warnings

import numpy as np

from ..boundary import DirichletSet
from ..errors import ConfigError, ForcingError, SolverError
from ..forces import Coriolis, OceanDrag, WindStress, evaluate_vector
from ..rheology import MaxwellEB
from ..stability import effective_dx
from .base import StepInfo
from .cuda_host import HostPath, fast_host_wanted
from .explicit import ExplicitSolver, check_substep_limit, stability_modulus

#: values of ``[solver] device``
DEVICES = ("cpu", "cuda")
#: keys of ``CudaExplicitSolver.kernel_timings`` [s] (see the class doc)
KERNELS = ("forcing", "setup", "substeps", "transfer")
SYNC_MODES = ("step", "explicit")
LAUNCH_MODES = ("auto", "cooperative", "launches")
#: state fields the device advances (their host copies go stale between steps in sync="explicit")
DEVICE_OWNED = ("velocity", "stress", "damage")
#: state fields only host code changes (mesh motion, thermodynamics, remapping): uploaded at every step
HOST_OWNED = ("thickness", "concentration", "cohesion")
STATE_FIELDS = DEVICE_OWNED + HOST_OWNED
_DEV_KEY = {"velocity": "vel", "stress": "sigma", "damage": "damage", "thickness": "h",
            "concentration": "conc", "cohesion": "coh"}


# ----------------------------------------------------------------------------
# availability
# ----------------------------------------------------------------------------
def simulator_enabled() -> bool:
    """True when numba runs CUDA kernels in its simulator (``NUMBA_ENABLE_CUDASIM=1``
    at numba's import)."""
    from numba import config

    return bool(config.ENABLE_CUDASIM)


@functools.lru_cache(maxsize=1)
def _compile_probe_error() -> str | None:
    """Compile (not launch) a one-line kernel for the current GPU; the error as text, or None.

    A GPU that numba finds can still be unusable: on the first GPU machine lagice ran on
    (2026-11-26), NVIDIA's ``numba-cuda`` target failed inside its own modules at the first
    compilation, because the installed numpy (2.5) no longer had an alias it uses. Without
    this probe that surfaced after the mesh was built, as an ``AttributeError`` deep in
    numba. Compiled once per process (about a second)."""
    try:
        from numba import cuda

        def _probe(a):
            i = cuda.grid(1)
            if i < a.size:
                a[i] = 2.0 * a[i]

        cuda.jit("void(float64[:])")(_probe)
    except Exception as exc:  # noqa: BLE001 - any compiler failure means "not usable"
        return " ".join(f"{type(exc).__name__}: {exc}".split())
    return None


def cuda_status() -> tuple[bool, str]:
    """``(usable, description)``: the GPU's name, the simulator, or why no GPU is usable
    (no device, or a device numba cannot compile for)."""
    if simulator_enabled():
        return True, "numba CUDA simulator (NUMBA_ENABLE_CUDASIM=1)"
    try:
        from numba import cuda

        if cuda.is_available():
            name = cuda.get_current_device().name
            name = name.decode() if isinstance(name, bytes) else str(name)
            err = _compile_probe_error()
            if err is None:
                return True, name
            return False, (f"numba finds the GPU ({name}) but cannot compile a kernel for it: {err}. A numba "
                           f"CUDA target and a numpy that do not match are a known cause (docs/gpu.md)")
        reason = f"numba.cuda.is_available() is False: {cuda.cuda_error() or 'no CUDA device found'}"
    except Exception as exc:  # noqa: BLE001 - any driver or toolkit failure means "not usable"
        reason = f"numba.cuda.is_available() is False: {type(exc).__name__}: {exc}"
    return False, " ".join(str(reason).split())


def require_cuda(key: str = "solver.device") -> str:
    """Raise :class:`ConfigError` naming ``key`` unless numba can use a CUDA GPU
    (or its simulator); returns the device description. No mesh; on a GPU, one
    one-line kernel compiled once per process."""
    ok, info = cuda_status()
    if not ok:
        raise ConfigError(
            f'{key} = "cuda": no CUDA GPU is usable on this machine ({info}). Use {key} = "cpu" (the '
            f"default), run on a machine with an NVIDIA GPU and the CUDA libraries numba needs (docs/gpu.md), "
            f"or set NUMBA_ENABLE_CUDASIM=1 to run the GPU kernels in numba's CUDA simulator (for tests: very "
            f"slow)")
    return info


def check_solver_device(sv: dict) -> None:
    """Check ``[solver] device`` of a scene before any mesh work (issue 15): a known
    value; for ``"cuda"``, the explicit stepper (the only one with a GPU version)
    and a usable GPU."""
    dev = sv.get("device", "cpu")
    if dev not in DEVICES:
        raise ConfigError(f"solver.device = {dev!r}: expected one of {list(DEVICES)}")
    if dev == "cuda":
        if sv.get("name") != "explicit":
            raise ConfigError(f'solver.device = "cuda" runs the explicit stepper only; solver.name = '
                              f'{sv.get("name")!r} has no GPU version (set solver.name = "explicit", or '
                              f'solver.device = "cpu")')
        if sv.get("volumetric_strain") not in (None, "element"):
            raise ConfigError(f"solver.volumetric_strain = {sv.get('volumetric_strain')!r}: the CUDA stepper uses "
                              f"each element's own volumetric strain only; set solver.device = \"cpu\", or leave "
                              f"solver.volumetric_strain unset")
        if sv.get("velocity_element") not in (None, "linear"):
            raise ConfigError(f"solver.velocity_element = {sv.get('velocity_element')!r}: the CUDA stepper has "
                              f"velocities at the nodes only; set solver.device = \"cpu\", or leave "
                              f"solver.velocity_element unset")
        require_cuda("solver.device")


# ----------------------------------------------------------------------------
# forcing fields on the device
# ----------------------------------------------------------------------------
class _NodeField:
    """A wind or ocean-current field at the nodes, for the device.

    ``path``: ``"device"`` (a vector :class:`forcing.records.RecordField` on a
    :class:`~forcing.records.RegularGrid` with ``rebuild_tolerance_m = 0``: the
    bracketing records live on the device, interpolation runs there),
    ``"constant"`` (a constant pair: filled on the device once per mesh),
    ``"zero"`` (absent), or ``"host"`` (anything else: callables, lon/lat grids,
    record fields with a rebuild tolerance: evaluated on the host at the nodes
    and copied over, 16 B per node per outer step).
    """

    def __init__(self, field, name: str, slots: tuple):
        from forcing.base import VECTOR
        from forcing.records import RecordField, RegularGrid

        self.field = field
        self.name = name
        self.c_out, self.c_bad = slots
        if field is None:
            self.path = "zero"
        elif isinstance(field, tuple):
            self.path = "constant"
        elif (isinstance(field, RecordField) and isinstance(field.grid, RegularGrid) and field.kind == VECTOR
              and field.rebuild_tolerance_m == 0.0):
            self.path = "device"
        else:
            self.path = "host"
        self._filled = None  # device array last filled with a constant
        self._recs = {}  # record index -> (host shape size, device array)
        self._blend = None  # ((i, j, a), device array)
        self._axes = None

    def device_bytes(self) -> int:
        out = sum(r.nbytes for _, r in self._recs.values())
        out += self._blend[1].nbytes if self._blend is not None else 0
        out += sum(a.nbytes for a in self._axes[:2]) if self._axes is not None else 0
        return out

    def _record(self, i):
        from numba import cuda

        if i not in self._recs:
            f = self.field
            rec = np.ascontiguousarray(f.grid.extend(f.source.read(i)), dtype=np.float64)
            self._recs[i] = (rec.size, cuda.to_device(rec))
        return self._recs[i]

    def evaluate(self, solver, t: float, out) -> None:
        """Fill the device array ``out`` (n, 2) [m s-1] for time ``t`` [s] (launches
        are asynchronous; outside-grid and non-finite counts go to the counters)."""
        from numba import cuda

        from . import cuda_kernels as K

        if self.path in ("zero", "constant"):
            if self._filled is not out:
                u, v = (0.0, 0.0) if self.path == "zero" else self.field
                solver._launch(K.fill_pair_kernel, out.shape[0], out, float(u), float(v))
                self._filled = out
            return
        if self.path == "host":
            vals = evaluate_vector(self.field, t, solver.mesh.nodes, self.name)
            solver._io.h2d(out, np.ascontiguousarray(vals, np.float64))
            return
        f = self.field
        if self._axes is None:
            self._axes = (cuda.to_device(np.ascontiguousarray(f._ax, np.float64)),
                          cuda.to_device(np.ascontiguousarray(f._ay, np.float64)),
                          int(f._uniform[0]), int(f._uniform[1]))
        ax, ay, ux, uy = self._axes
        i, j, a = f._bracket(t)  # same bracket, extrapolation policy and errors as the CPU
        size0, r0 = self._record(i)
        _, r1 = self._record(j)
        for k in list(self._recs):
            if k != i and k != j:
                del self._recs[k]
                self._blend = None
        n = out.shape[0]
        nc = r0.shape[0]
        if i == j or a == 0.0:
            src0, src1, two = r0, r0, 0
        elif size0 <= nc * n:
            # grid smaller than the points: blend in time on the grid once per (i, j, a)
            if self._blend is None or self._blend[0] != (i, j, a):
                buf = self._blend[1] if self._blend is not None else cuda.device_array(r0.shape, np.float64)
                solver._launch(K.blend_records_kernel, size0, r0, r1, float(a), buf)
                self._blend = ((i, j, a), buf)
            src0, src1, two = self._blend[1], self._blend[1], 0
        else:
            src0, src1, two = r0, r1, 1
        clamp = int(f.space_extrapolation == "clamp")
        solver._launch(K.record_field_kernel, n, solver._d["nodes"], ax, ay, ux, uy, clamp, src0, src1,
                       float(a), two, out, solver._d["counters"], self.c_out, self.c_bad)

    def check(self, counters, t: float, nodes) -> None:
        """After the mid-step sync: raise the CPU's :class:`ForcingError` (replayed on
        the host for its message) if the device met points outside the grid or
        non-finite values."""
        if self.path != "device":
            return
        n_out, n_bad = int(counters[self.c_out]), int(counters[self.c_bad])
        if n_out or n_bad:
            evaluate_vector(self.field, t, nodes, self.name)  # raises with the CPU's message
            raise ForcingError(f"{self.name}: the device interpolation met {n_out} points outside the "
                               f"forcing grid and {n_bad} non-finite values at t = {t} s, but the host "
                               f"evaluation did not (a bug: please report)")

    def reset(self):
        self._filled = None


# ----------------------------------------------------------------------------
# the stepper
# ----------------------------------------------------------------------------
def check_cuda_substep_limit(substep_limit, crack_closure: bool) -> str:
    """``solver.substep_limit`` for the CUDA stepper: as the CPU stepper's
    (:func:`lagice.solvers.explicit.check_substep_limit`), but ``"element"`` with
    ``rheology.crack_closure`` is refused (ConfigError naming both keys): its element-wise
    bound needs max E0 exp(−c*(1−A))/area, and the element areas live on the device (the
    CPU stepper implements it)."""
    limit = check_substep_limit(substep_limit)
    if limit == "element" and crack_closure:
        raise ConfigError("solver.substep_limit = 'element' with rheology.crack_closure = true: the CUDA stepper "
                          "does not implement the element-wise limit of closed cracks; use substep_limit = 'mesh' "
                          "(the default) or solver.device = 'cpu'")
    return limit


class CudaExplicitSolver:
    """Explicit Maxwell-EB time stepper on a CUDA GPU (``[solver] device = "cuda"``).

    Args (as :class:`~lagice.solvers.explicit.ExplicitSolver`):
        rheology, mesh, bcs, forces (``WindStress``, ``OceanDrag``, ``Coriolis``;
        at most one of each of the first two), substeps, heal_rate (``(state, t_s)
        -> (m,) [s-1]``), safety, allow_unstable.
        parallel: the CPU stepper's choice of kernel builds; accepted so that a
            scene's ``[solver]`` options work on both devices, and without effect
            here (the CPU builds give bit-identical results either way).
    Device options (keyword only):
        sync: ``"step"`` (default): the host state (velocity, stress, damage) is
            brought up to date after every step and uploaded again before the
            next, so any host code may read and write it between steps;
            ``"explicit"``: the state stays on the device between steps and
            host code asks for it with :meth:`to_host` (the model does:
            :meth:`lagice.model.Model.needs_host_state`; ``docs/gpu.md``: who
            calls what, when).
        launch: ``"auto"`` (cooperative single-launch sub-step loop where
            possible, else ``"launches"``), ``"cooperative"``, ``"launches"``
            (two kernels per sub-step).
        threads_per_block: CUDA block size (default 128).
        max_blocks: cap on blocks per launch (None: one thread per entity; every
            kernel is a grid-stride loop, so any cap is correct).
        max_registers: register cap per thread for the cooperative sub-step kernel
            (None: the compiler's choice, 86 on sm_90). A cap raises the number of
            co-resident blocks and may make ptxas spill to local memory; the
            results are the same (``docs/gpu.md``, "a register cap").
        fast_host: copies through the CUDA driver directly and launches with prepared
            arguments (:mod:`lagice.solvers.cuda_host`); None (default): on a GPU
            unless ``LAGICE_CUDA_FAST_HOST=0``, never in the simulator; False: numba's
            own copies and launches. Bit for bit the same results.

    After a step, ``state.velocity`` is the last sub-step's velocity (in
    ``sync="explicit"`` once downloaded), :attr:`transport_velocity` the mean
    over the sub-steps and :attr:`last_strain_rate` its strain rate (both
    downloaded on first access after a step); ``area``, ``b``, ``c``, ``td`` on
    first access after a geometry update; ``dx_min``, ``last_substeps``.
    ``kernel_timings`` [s]: ``forcing`` (host forcing work and record uploads),
    ``setup`` (device setup through the mid-step sync), ``substeps`` (sub-step
    loop, mean velocity and strain rate, to the end-of-step sync),
    ``transfer`` (state uploads at the start of the step and, in
    ``sync="step"``, the download at its end). ``StepInfo.timings`` maps them
    as assembly = forcing + setup + transfer, solve = substeps, damage = 0
    (fused into the sub-step kernels).
    """

    name = "explicit"
    device = "cuda"

    def __init__(self, rheology: MaxwellEB, mesh, bcs=(), forces=(), substeps: int | None = None,
                 heal_rate=None, safety: float = 0.7, allow_unstable: bool = False,
                 parallel: bool | None = None, *, sync: str = "step", launch: str = "auto",
                 threads_per_block: int = 128, max_blocks: int | None = None, substep_limit: str = "mesh",
                 max_registers: int | None = None, fast_host: bool | None = None):
        self.device_name = require_cuda("solver.device")
        if not isinstance(rheology, MaxwellEB):
            raise ConfigError(f"the explicit stepper solves the Maxwell-EB rheology; got {type(rheology).__name__}")
        rheology.require_stepper("explicit_cuda")
        if substeps is not None:
            if int(substeps) != substeps or int(substeps) < 1:
                raise ConfigError(f"substeps = {substeps!r} must be an integer >= 1 (or None: automatic)")
            substeps = int(substeps)
        if not 0.0 < safety <= 1.0:
            raise ConfigError(f"safety = {safety!r} must be in (0, 1]")
        if sync not in SYNC_MODES:
            raise ConfigError(f"sync = {sync!r}: expected one of {list(SYNC_MODES)}")
        if launch not in LAUNCH_MODES:
            raise ConfigError(f"launch = {launch!r}: expected one of {list(LAUNCH_MODES)}")
        if int(threads_per_block) != threads_per_block or not 1 <= threads_per_block <= 1024:
            raise ConfigError(f"threads_per_block = {threads_per_block!r} must be an integer in [1, 1024]")
        if max_blocks is not None and (int(max_blocks) != max_blocks or max_blocks < 1):
            raise ConfigError(f"max_blocks = {max_blocks!r} must be an integer >= 1 or None")
        if max_registers is not None and (int(max_registers) != max_registers or not 16 <= max_registers <= 255):
            raise ConfigError(f"max_registers = {max_registers!r} must be an integer in [16, 255] or None")
        from . import cuda_kernels as K

        self.substep_limit = check_cuda_substep_limit(substep_limit, rheology.params.crack_closure)
        self.rheology = rheology
        self.bcs = list(bcs)
        self.forces = list(forces)
        self.substeps = substeps
        self.safety = float(safety)
        self.allow_unstable = bool(allow_unstable)
        self.heal_rate = heal_rate
        self.parallel = parallel
        self.sync = sync
        self.launch = launch
        self.launch_used = None  # "cooperative" or "launches", set at the first step
        self.launch_note = ""
        self.tpb = int(threads_per_block)
        self.max_blocks = None if max_blocks is None else int(max_blocks)
        self.max_registers = None if max_registers is None else int(max_registers)
        self.kernel_timings = {k: 0.0 for k in KERNELS}
        #: copies and launches (direct driver calls and prepared launches on a GPU: cuda_host.py)
        self._io = HostPath((fast_host_wanted() and not simulator_enabled()) if fast_host is None
                            else bool(fast_host))
        self._io_logged = None
        self._cnt0 = np.zeros(K.N_COUNTERS, np.int64)
        self._sc0 = np.zeros(K.N_SCALARS)
        self._sc0[[K.S_E_MAX, K.S_STIFF_MAX]] = -math.inf
        self._sc0[K.S_AREA_MIN] = math.inf
        self._checked = set()
        self.last_substeps = None
        self._d = {}
        self._coop_max = None
        self._wind = self._ocean = None
        self._c_air = 0.0
        self._drag_coef, self._cos_t, self._sin_t = 0.0, 1.0, 0.0
        self._f_cor = 0.0
        for f in self.forces:
            if isinstance(f, WindStress):
                if self._wind is not None:
                    raise ConfigError("the CUDA stepper takes one WindStress force; combine the winds into one field")
                self._wind = _NodeField(f.wind, "wind", (K.C_WIND_OUT, K.C_WIND_BAD))
                self._c_air = f.rho_air * f.drag
            elif isinstance(f, OceanDrag):
                if self._ocean is not None:
                    raise ConfigError("more than one OceanDrag force given; combine them into one")
                self._ocean = _NodeField(f.current, "ocean current", (K.C_OCEAN_OUT, K.C_OCEAN_BAD))
                self._drag_coef = f.rho_water * f.drag
                self._cos_t, self._sin_t = f.cos_turn, f.sin_turn
            elif isinstance(f, Coriolis):
                self._f_cor += f.f
            else:
                raise ConfigError(f"force {f!r}: the CUDA stepper evaluates WindStress, OceanDrag and Coriolis "
                                  "forces only (use solver.device = 'cpu' for other forces)")
        if self._ocean is None:
            self._ocean = _NodeField(None, "ocean current", (K.C_OCEAN_OUT, K.C_OCEAN_BAD))
        self._pres_static = all(not callable(bc.u) and not callable(bc.v) for bc in self.bcs)
        self.reset_topology(mesh)

    # -- sub-step choice: the CPU stepper's own rules (same N, same refusals) -------
    substeps_for = ExplicitSolver.substeps_for
    _check_stability = ExplicitSolver._check_stability
    _substep_factor = ExplicitSolver._substep_factor
    velocity_element = "linear"  # the CUDA stepper's velocities are at the nodes (refused otherwise)

    # -- forcing paths (documentation, tests) ---------------------------------------
    @property
    def forcing_paths(self) -> dict:
        """``{"wind": path, "ocean": path}``, path in device/constant/zero/host (see ``_NodeField``)."""
        return {"wind": self._wind.path if self._wind is not None else "zero", "ocean": self._ocean.path}

    # -- launch helpers ----------------------------------------------------------------
    def _blocks(self, size: int) -> int:
        nb = max(1, -(-int(size) // self.tpb))
        return nb if self.max_blocks is None else min(nb, self.max_blocks)

    def _launch(self, kernel, size: int, *args) -> None:
        self._io.launch(kernel, self._blocks(size), self.tpb, args)

    # -- topology and geometry (the device node system) ---------------------------------
    def reset_topology(self, mesh) -> None:
        """New mesh (remesh, checkpoint load): drop every device array and rebuild the
        prescribed dofs; the next :meth:`step` uploads the whole state from the host."""
        self._io.clear()
        self._d = {}
        self._resident = None
        self._host_stale = set()
        self._host_ref = {}
        self._geom_cache = {}
        self._have_results = False
        self._transport = self._strain = None
        self._last_check = None
        for f in (self._wind, self._ocean):
            if f is not None:
                f.reset()
        self._heal_const = None
        self._pres_done = False
        self.mesh = mesh
        self.dirichlet = DirichletSet(mesh, self.bcs)  # as lagice.fem.NodeSystem
        fixed = np.zeros((mesh.n_nodes, 2), np.int8)
        fixed.reshape(-1)[self.dirichlet.dofs] = 1
        self.fixed = fixed
        self.update_geometry()

    def _ensure_topology(self) -> None:
        if self._d:
            return
        from numba import cuda

        from . import cuda_kernels as K

        mesh = self.mesh
        n, m = mesh.n_nodes, mesh.n_elements
        ptr, elems, local = mesh.node_elements
        idx = np.int32 if max(3 * m, n) < 2**31 - 1 else np.int64
        d = self._d
        d["tri"] = cuda.to_device(np.ascontiguousarray(mesh.triangles, idx))
        d["ptr"] = cuda.to_device(np.ascontiguousarray(ptr, idx))
        d["elems"] = cuda.to_device(np.ascontiguousarray(elems, idx))
        d["local"] = cuda.to_device(np.ascontiguousarray(local, np.int8))
        d["fixed"] = cuda.to_device(np.ascontiguousarray(self.fixed, np.int8))
        dofs = np.ascontiguousarray(self.dirichlet.dofs, idx)
        d["dofs"] = cuda.to_device(dofs) if len(dofs) else None
        f8 = np.float64
        for key, shape in (("nodes", (n, 2)), ("b", (m, 3)), ("c", (m, 3)), ("area", m), ("td", m),
                           ("vel", (n, 2)), ("vel_w", (n, 2)), ("sigma", (m, 3)), ("sigma_w", (m, 3)),
                           ("damage", m), ("damage_w", m), ("h", m), ("conc", m), ("coh", m),
                           ("conc_factor", m), ("sig_c", m), ("sig_t", m), ("e_dt", m), ("gamma", m),
                           ("heal", m), ("m_dt", n), ("fext", (n, 2)), ("cda", n), ("half_mf", n),
                           ("wb", len(elems)), ("wc", len(elems)), ("wind", (n, 2)), ("current", (n, 2)),
                           ("vel_sum", (n, 2)), ("mean_vel", (n, 2)), ("strain", (m, 3))):
            d[key] = cuda.device_array(shape, f8)
        d["flag"] = cuda.device_array(m, np.int8)
        # neXtSIM's compressive term: P_max per element, refreshed each step (a placeholder when off)
        d["pmax"] = cuda.device_array(m if self.rheology.params.max_pressure_pa else 1, f8)
        d["pres0"] = cuda.to_device(np.zeros((n, 2)))
        d["pres1"] = cuda.to_device(np.zeros((n, 2)))
        d["counters"] = cuda.device_array(K.N_COUNTERS, np.int64)
        d["scalars"] = cuda.device_array(K.N_SCALARS, f8)
        self._index_dtype = idx

    def _reset_counters(self) -> None:
        self._io.h2d(self._d["counters"], self._cnt0)
        self._io.h2d(self._d["scalars"], self._sc0)

    def update_geometry(self) -> None:
        """Nodes moved on the host (mesh motion): upload them and recompute shape
        gradients, areas, td and ``dx_min`` on the device."""
        from . import cuda_kernels as K

        self._ensure_topology()
        d = self._d
        self._io.h2d(d["nodes"], np.ascontiguousarray(self.mesh.nodes, np.float64))
        self._reset_counters()
        self._launch(K.geometry_kernel, self.mesh.n_elements, d["nodes"], d["tri"], d["b"], d["c"], d["area"],
                     d["td"], float(self.rheology.params.shear_wave_speed), d["scalars"], d["counters"])
        cnt = self._io.d2h(d["counters"])
        sc = self._io.d2h(d["scalars"])
        self._geom_cache = {}
        if cnt[K.C_INVERTED]:
            raise SolverError(f"{int(cnt[K.C_INVERTED])} inverted elements in the mesh")
        self.dx_min = float(np.sqrt(2.0 * sc[K.S_AREA_MIN]))
        self.dx_eff = self.dx_min

    def _geom(self, key):
        if key not in self._geom_cache:
            self._geom_cache[key] = self._io.d2h(self._d[key])
        return self._geom_cache[key]

    area = property(lambda self: self._geom("area"), doc="element areas [m²] (host copy, cached)")
    b = property(lambda self: self._geom("b"), doc="∂φ/∂x [m-1] (host copy, cached)")
    c = property(lambda self: self._geom("c"), doc="∂φ/∂y [m-1] (host copy, cached)")
    td = property(lambda self: self._geom("td"), doc="damage time td [s] (host copy, cached)")

    # -- results downloaded on demand ------------------------------------------------------
    @property
    def transport_velocity(self):
        """(n, 2) [m s-1] mean of the last step's sub-step velocities (what moves the
        nodes; :class:`~lagice.solvers.base.TimeStepper`), None before a step."""
        if self._transport is None and self._have_results:
            self._transport = self._io.d2h(self._d["mean_vel"])
        return self._transport

    @property
    def last_strain_rate(self):
        """(m, 3) [s-1] strain rate of :attr:`transport_velocity`, None before a step."""
        if self._strain is None and self._have_results:
            self._strain = self._io.d2h(self._d["strain"])
        return self._strain

    # -- sync API ---------------------------------------------------------------------------
    @property
    def host_stale(self) -> tuple:
        """State fields whose host copy is older than the device's (``sync="explicit"``)."""
        return tuple(f for f in DEVICE_OWNED if f in self._host_stale)

    def to_host(self, state, fields=DEVICE_OWNED) -> None:
        """Bring the device-advanced ``fields`` (default: velocity, stress, damage) of
        ``state`` up to date on the host (new host arrays, as the CPU stepper assigns
        them). In ``sync="explicit"``, call before host code reads or edits them
        (:meth:`lagice.model.Model.needs_host_state` does). Free when the host copy
        is current or the device does not hold ``state``."""
        for f in fields:
            if f not in STATE_FIELDS:
                raise ConfigError(f"to_host: unknown field {f!r}; expected some of {list(STATE_FIELDS)}")
        if self._resident is not state:
            return
        for f in fields:
            if f in self._host_stale:
                arr = self._io.d2h(self._d[_DEV_KEY[f]])
                setattr(state, f, arr)
                self._host_ref[f] = arr
                self._host_stale.discard(f)

    def from_host(self, state, fields=None) -> None:
        """Upload ``fields`` (default: all of :data:`STATE_FIELDS`) of ``state`` to the
        device now. :meth:`step` does this by itself for every field whose host copy
        may have changed (docs/gpu.md); a state the device has not seen is uploaded whole."""
        self._ensure_topology()
        if self._resident is not state:
            fields = STATE_FIELDS
            self._host_stale = set()
        fields = STATE_FIELDS if fields is None else tuple(fields)
        n, m = self.mesh.n_nodes, self.mesh.n_elements
        for f in fields:
            if f not in STATE_FIELDS:
                raise ConfigError(f"from_host: unknown field {f!r}; expected some of {list(STATE_FIELDS)}")
            host = getattr(state, f)
            shape = {"velocity": (n, 2), "stress": (m, 3)}.get(f, (m,))
            arr = np.ascontiguousarray(host, np.float64)
            if arr.shape != shape:
                raise SolverError(f"state.{f} has shape {arr.shape}; expected {shape} for this mesh "
                                  "(call reset_topology after replacing the mesh)")
            self._io.h2d(self._d[_DEV_KEY[f]], arr)
            self._host_ref[f] = host
            self._host_stale.discard(f)
        self._resident = state

    def _upload_for_step(self, state) -> None:
        """Before a step: the host-owned fields, and every device-owned field whose host
        copy is current (host code may have edited it since it was downloaded) or was
        replaced by a new array (assigned on the host)."""
        if self._resident is not state:
            self.from_host(state)
            return
        fields = list(HOST_OWNED)
        for f in DEVICE_OWNED:
            if f not in self._host_stale or getattr(state, f) is not self._host_ref.get(f):
                fields.append(f)
        self.from_host(state, fields)

    def device_check(self, max_speed_m_s: float) -> tuple[tuple, bool]:
        """For the NaN checker (:class:`lagice.activities.NaNChecker`): ``(fields, ok)``
        where ``fields`` are the state fields whose host copies are stale and ``ok``
        is True when the device found them finite at the end of the last step, with
        every ice speed below ``max_speed_m_s`` [m s-1] — the host may then skip them.
        ``ok`` False: download them and check on the host (the host names the place)."""
        stale = self.host_stale
        if not stale or self._last_check is None:
            return (), True
        bad_nodes, bad_elems, speed2 = self._last_check
        # margin: the host's np.hypot may differ from sqrt(u² + v²) in the last bit
        ok = bad_nodes == 0 and bad_elems == 0 and math.sqrt(speed2) <= max_speed_m_s * (1.0 - 1e-9)
        return stale, ok

    def device_bytes(self) -> int:
        """Bytes held in device arrays (mesh, state, work arrays, forcing records)."""
        out = sum(a.nbytes for a in self._d.values() if a is not None)
        for f in (self._wind, self._ocean):
            if f is not None:
                out += f.device_bytes()
        return out

    # -- the step -----------------------------------------------------------------------------
    def _choose_launch(self, args, optional: bool = False) -> str:
        """Cooperative single-launch loop where requested and possible (``optional``: the
        kernel with the optional rheology terms, which the rheology fixes for the stepper's life)."""
        from . import cuda_kernels as K

        if self.launch_used is not None:
            return self.launch_used
        if self.launch == "launches":
            self.launch_used = "launches"
            return self.launch_used
        try:
            kern = K.cooperative_kernel(self.max_registers, optional)
            if simulator_enabled():
                mx = kern.overloads[None].max_cooperative_grid_blocks(self.tpb)
            else:
                from numba import typeof

                mx = kern.compile(tuple(typeof(a) for a in args)).max_cooperative_grid_blocks(self.tpb)
            if mx < 1:
                raise SolverError(f"no block of {self.tpb} threads of the cooperative kernel fits on the device")
            self._coop_max = int(mx)
            self.launch_used = "cooperative"
        except Exception as exc:  # noqa: BLE001 - compile, link or driver failures all mean "not available"
            if self.launch == "cooperative":
                raise SolverError(f"launch = 'cooperative' is not available on {self.device_name}: {exc}") from exc
            self.launch_note = f"cooperative sub-step kernel unavailable ({type(exc).__name__}: {exc})"
            warnings.warn(f"{self.launch_note}; using two launches per sub-step", RuntimeWarning, stacklevel=3)
            self.launch_used = "launches"
        return self.launch_used

    def step(self, state, t_s: float, dt_s: float) -> StepInfo:
        """Advance velocity, stress and damage of ``state`` over [t_s, t_s + dt_s]
        (:class:`~lagice.solvers.base.TimeStepper`). A stability ConfigError or a
        ForcingError leaves the state untouched; a non-finite result is committed,
        as on the CPU, for the NaN checker to report."""
        from . import cuda_kernels as K

        if not dt_s > 0:
            raise ConfigError(f"dt = {dt_s!r} s must be > 0")
        if state.mesh is not self.mesh:
            raise SolverError("state.mesh is not this stepper's mesh: call reset_topology(state.mesh) after "
                              "replacing the mesh (remesh, checkpoint load)")
        kt = {k: 0.0 for k in KERNELS}
        t0 = time.perf_counter()
        if self.sync == "step":
            self.from_host(state)
        else:
            self._upload_for_step(state)
        d = self._d
        rh, p = self.rheology, self.rheology.params
        t1 = time.perf_counter()
        kt["transfer"] = t1 - t0

        # -- host side of the forcing; device forcing kernels (asynchronous) ----------------
        self._reset_counters()
        mesh = self.mesh
        n, m = mesh.n_nodes, mesh.n_elements
        t_new = t_s + dt_s
        self._launch(K.prepare_elements_kernel, m, d["damage"], d["sigma"], d["conc"], d["coh"], d["area"],
                     float(p.E0),
                     float(p.relaxation_time_s), float(p.concentration_c), float(p.alpha), rh._denom, rh.q,
                     d["damage_w"], d["sigma_w"], d["e_dt"], d["gamma"], d["conc_factor"], d["sig_c"],
                     d["sig_t"], d["flag"], d["scalars"])
        use_pmax = int(bool(p.max_pressure_pa))
        if use_pmax:
            self._launch(K.max_pressure_kernel, m, d["h"], d["conc_factor"], float(p.max_pressure_pa),
                         float(p.max_pressure_thickness_exponent), d["pmax"])
        if self._wind is not None:
            self._wind.evaluate(self, t_new, d["wind"])
        self._ocean.evaluate(self, t_new, d["current"])
        if self.heal_rate is not None:
            self.to_host(state, ("damage",))  # the callable reads the host state (start-of-step damage)
            heal = np.ascontiguousarray(self.heal_rate(state, t_s), np.float64)
            if heal.shape != (m,):
                raise SolverError(f"heal_rate returned shape {heal.shape}; expected ({m},) [s-1]")
            self._io.h2d(d["heal"], heal)
            self._heal_const = None
        else:
            rate = float(rh.constant_heal_rate(1)[0])
            if self._heal_const != rate:
                self._launch(K.fill_kernel, m, d["heal"], rate)
                self._heal_const = rate
        if d["dofs"] is not None and not (self._pres_static and self._pres_done):
            from numba import cuda

            v0 = cuda.to_device(np.ascontiguousarray(self.dirichlet.values(t_s), np.float64))
            v1 = cuda.to_device(np.ascontiguousarray(self.dirichlet.values(t_new), np.float64))
            self._launch(K.scatter_prescribed_kernel, v0.shape[0], d["dofs"], v0, v1, d["pres0"], d["pres1"])
            self._pres_done = True
        t2 = time.perf_counter()
        kt["forcing"] = t2 - t1

        # -- mid-step sync: E_max, forcing checks, sub-step count ------------------------------
        cnt = self._io.d2h(d["counters"])
        scal = self._io.d2h(d["scalars"])
        E_max = float(scal[K.S_E_MAX]) if m else float(p.E0)
        if p.crack_closure and m:
            # closed cracks respond with the undamaged modulus: the limit takes E0 exp(−c*(1−A)), on
            # the host from the host's concentration (thermodynamics keeps it there), with the CPU
            # stepper's expression (explicit.stability_modulus), so both take the same sub-steps
            E_max = float(stability_modulus(p, None, state.concentration).max())
        self.dx_eff = (effective_dx(self.dx_min, E_max, float(scal[K.S_STIFF_MAX]))
                       if m and self.substep_limit == "element" else self.dx_min)
        n_sub = self.substeps_for(dt_s, E_max)
        dt_sub = dt_s / n_sub
        self._check_stability(dt_sub, E_max)
        if self._wind is not None:
            self._wind.check(cnt, t_new, mesh.nodes)
        self._ocean.check(cnt, t_new, mesh.nodes)
        self._launch(K.finish_moduli_kernel, m, d["e_dt"], d["gamma"], dt_sub)
        self._launch(K.prepare_nodes_kernel, n, d["ptr"], d["elems"], d["local"], d["area"], d["h"], d["b"],
                     d["c"], float(p.rho_ice), dt_sub, d["wind"], int(self._wind is not None), self._c_air,
                     self._drag_coef, self._f_cor, d["vel"], d["vel_w"], d["vel_sum"], d["m_dt"], d["fext"],
                     d["cda"], d["half_mf"], d["wb"], d["wc"])
        t3 = time.perf_counter()
        kt["setup"] = t3 - t2

        # -- the sub-step loop -------------------------------------------------------------------
        nu = p.poisson
        kxx, kxy, kss = 1.0 / (1.0 - nu * nu), nu / (1.0 - nu * nu), (1.0 - nu) / (1.0 - nu * nu)
        node_args = (d["vel_w"], d["vel_sum"], d["sigma_w"], d["ptr"], d["elems"], d["wb"], d["wc"], d["m_dt"],
                     d["fext"], d["cda"], d["current"], self._cos_t, self._sin_t, d["half_mf"], d["fixed"],
                     d["pres0"], d["pres1"])
        # the CPU kernel's optional terms; its None is 0 here (a CUDA launch cannot pass None)
        # bit flags (cuda_kernels.element_update): 1 keep the mean stress, 2 the effective failure
        # stress, 4 closed cracks
        keep_mean = ((0 if p.relax_mean_stress else 1) | (2 if p.failure_stress == "effective" else 0)
                     | (4 if p.crack_closure else 0))
        theta = float(p.mean_fraction) if p.stress_correction == "mean_stress" else 0.0
        dilat = float(p.dilatancy_factor or 0.0)
        mat = (d["conc_factor"], d["coh"], d["sig_c"], d["sig_t"], d["td"], d["heal"], d["e_dt"], d["gamma"],
               d["pmax"], use_pmax, keep_mean, theta, dilat)
        consts = (kxx, kxy, kss, rh.q, rh._denom, float(p.max_damage), float(p.E0),
                  float(p.relaxation_time_s), float(p.alpha))
        coop_args = (n_sub, dt_sub, *node_args, d["tri"], d["b"], d["c"], d["damage_w"], *mat, *consts,
                     d["flag"], d["mean_vel"], d["strain"], d["counters"], d["scalars"])
        optional = bool(keep_mean or theta or dilat)
        if self._choose_launch(coop_args, optional) == "cooperative":
            blocks = min(self._coop_max, self._blocks(max(n, m)))
            self._io.launch(K.cooperative_kernel(self.max_registers, optional), blocks, self.tpb, coop_args)
        else:
            elem_args = (d["tri"], d["b"], d["c"], d["vel_w"], d["sigma_w"], d["damage_w"], *mat, *consts,
                         d["flag"], d["counters"])
            element_kernel = K.optional_kernels()["element_substep_kernel"] if optional else K.element_substep_kernel
            for k in range(n_sub):
                self._launch(K.node_substep_kernel, n, (k + 1) / n_sub, *node_args)
                self._launch(element_kernel, m, dt_sub, *elem_args)
            self._launch(K.finish_nodes_kernel, n, n_sub, d["vel_w"], d["vel_sum"], d["mean_vel"], d["counters"],
                         d["scalars"])
            self._launch(K.finish_elements_kernel, m, d["tri"], d["b"], d["c"], d["mean_vel"], d["strain"],
                         d["flag"], d["sigma_w"], d["damage_w"], d["counters"])
        cnt = self._io.d2h(d["counters"])
        speed2 = float(self._io.d2h(d["scalars"])[K.S_SPEED2_MAX])
        t4 = time.perf_counter()
        kt["substeps"] = t4 - t3

        # -- commit: the working arrays become the state -----------------------------------------
        for a, w in (("vel", "vel_w"), ("sigma", "sigma_w"), ("damage", "damage_w")):
            d[a], d[w] = d[w], d[a]
        self._host_stale = set(DEVICE_OWNED)
        self._transport = self._strain = None
        self._have_results = True
        self._last_check = (int(cnt[K.C_NONFINITE]), int(cnt[K.C_NONFINITE_ELEM]), speed2)
        self.last_substeps = n_sub
        n_capped = int(cnt[K.C_CAPPED])
        rh.n_capped_total += n_capped
        if self.sync == "step":
            self.to_host(state)
            kt["transfer"] += time.perf_counter() - t4
        for k, v in kt.items():
            self.kernel_timings[k] += v
        io_state = (self.launch_used, self._io.fast, self._io.prepared_launches, self._io.note)
        if io_state != self._io_logged:  # the first step, and whenever the host path falls back
            self._io_logged = io_state
            import logging

            logging.getLogger("lagice").info(
                f"GPU stepper on {self.device_name}: launch {self.launch_used}; host path: "
                f"{'direct driver copies' if self._io.fast else 'numba copies'}, "
                f"{'prepared launches' if self._io.prepared_launches else 'numba launches'}"
                + (f" ({self._io.note})" if self._io.note else ""))
        info = StepInfo(iterations=n_sub, residual=0.0, n_damaged=int(cnt[K.C_DAMAGED]), n_capped=n_capped)
        info.timings = {"assembly": kt["forcing"] + kt["setup"] + kt["transfer"], "solve": kt["substeps"],
                        "damage": 0.0}
        info.kernel_timings = kt
        return info
