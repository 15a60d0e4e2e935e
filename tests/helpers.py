"""Small helpers shared by the tests (imported as ``from helpers import ...``)."""
import weakref

import numpy as np

_CLOCKS = weakref.WeakKeyDictionary()


def step(stepper, state, dt):
    """Advance a bare time stepper one step of ``dt`` [s], keeping the time of
    ``state`` the way :class:`lagice.model.Model` keeps its clock (stepper unit
    tests only; everything else goes through Model/Simulation)."""
    clocks = _CLOCKS.setdefault(stepper, {})
    t = clocks.get(id(state), 0.0)
    info = stepper.step(state, t, dt)
    clocks[id(state)] = t + dt
    return info


QUIET = {"run.progress": False, "output.plot": False}


def scene_sim(name, out_dir, overrides=None):
    """A Simulation of a bundled scene with ``overrides`` (quiet, no plot), writing to ``out_dir``."""
    from lagice.scenes.builder import build_simulation
    from lagice.scenes.config import load_scene

    return build_simulation(load_scene(name, {**QUIET, **(overrides or {})}), out_dir)


def series(sim, name):
    """The recorded values of time-series diagnostic ``name`` after the initial record."""
    import numpy as np

    return np.array(sim.activities["timeseries"].writer.rows[name][1:])


def shear_inner_nodes(mesh, amplitude_m=8e3, wavelength_m=80e3):
    """Move the interior nodes of ``mesh`` in place by ``amplitude_m`` sin(y/``wavelength_m``) in x
    (the boundary nodes stay), distorting the elements as a Lagrangian step would."""
    inner = np.ones(mesh.n_nodes, bool)
    inner[np.unique(mesh.boundary_edges)] = False
    mesh.nodes[inner, 0] += amplitude_m * np.sin(mesh.nodes[inner, 1] / wavelength_m)


def global_remesh(model, dt_s=3600.0):
    """Force one global remesh through the model's ``remeshing`` component (which makes new
    elements); asserts that it happened and returns its event."""
    rem = model.component("remeshing")
    rem.options["force_global"] = True
    ev = rem.advance(model, dt_s)
    assert ev is not None and ev.kind == "global"
    return ev


def compression_overrides(n_across=10, **kw):
    """Overrides of the uniaxial_compression scene for N elements across the short edge."""
    return {"domain.resolution_m": 100e3 / n_across, **kw}


def node_constants_reference(m_dt, cda, mass, coriolis, fext, current):
    """The (n, 8) per-node constants of the explicit node kernel
    (``lagice.solvers.explicit.NODE_CONSTANTS``) from their parts, with the arithmetic of the
    stepper's one-pass set-up (½ m f as (0.5 m) f): the reference its test compares with."""
    nc = np.zeros((len(m_dt), 8))
    nc[:, 0], nc[:, 1], nc[:, 2] = m_dt, cda, 0.5 * mass * coriolis
    nc[:, 3:5], nc[:, 5:7] = fext, current
    return nc
