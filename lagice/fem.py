"""P1/P0 finite-element building blocks: shape-function gradients, strain
rates, nodal forces, lumped mass, assembly on a fixed sparsity pattern, and the
lumped-mass node system the sub-stepped time steppers compose
(:class:`NodeSystem`: prescribed dofs, geometry, lumped mass, adjacency weights,
and the 2×2 node solve :func:`solve_node_2x2`).

Degrees of freedom are interleaved: dof 2i is u (x velocity) of node i and
dof 2i+1 is v. All loops over elements are numba kernels.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit, prange

from ._numba import PARALLEL_MIN_SIZE, serial_copy
from .boundary import DirichletSet
from .errors import SolverError


@njit(cache=True, parallel=True)
def shape_gradients(nodes, tri):
    """P1 gradients: b[e,k] = ∂φk/∂x, c[e,k] = ∂φk/∂y [m-1] and signed area [m²]."""
    m = tri.shape[0]
    b = np.empty((m, 3))
    c = np.empty((m, 3))
    area = np.empty(m)
    for e in prange(m):
        i, j, k = tri[e, 0], tri[e, 1], tri[e, 2]
        x0, y0 = nodes[i, 0], nodes[i, 1]
        x1, y1 = nodes[j, 0], nodes[j, 1]
        x2, y2 = nodes[k, 0], nodes[k, 1]
        a2 = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        area[e] = 0.5 * a2
        inv = 1.0 / a2
        b[e, 0] = (y1 - y2) * inv
        b[e, 1] = (y2 - y0) * inv
        b[e, 2] = (y0 - y1) * inv
        c[e, 0] = (x2 - x1) * inv
        c[e, 1] = (x0 - x2) * inv
        c[e, 2] = (x1 - x0) * inv
    return b, c, area


@njit(cache=True, inline="always")
def element_strain_rate(tri, b, c, vel, e):
    """(ε̇xx, ε̇yy, ε̇xy) [s-1] of element e from nodal velocity (n, 2); the one
    place this arithmetic lives (fused solver kernels inline it)."""
    exx = 0.0
    eyy = 0.0
    exy = 0.0
    for k in range(3):
        u = vel[tri[e, k], 0]
        v = vel[tri[e, k], 1]
        exx += b[e, k] * u
        eyy += c[e, k] * v
        exy += c[e, k] * u + b[e, k] * v
    return exx, eyy, 0.5 * exy


@njit(cache=True, parallel=True)
def strain_rate(tri, b, c, vel):
    """Element strain rate (ε̇xx, ε̇yy, ε̇xy) [s-1] from nodal velocity (n, 2)."""
    m = tri.shape[0]
    out = np.empty((m, 3))
    for e in prange(m):
        exx, eyy, exy = element_strain_rate(tri, b, c, vel, e)
        out[e, 0] = exx
        out[e, 1] = eyy
        out[e, 2] = exy
    return out


@njit(cache=True, parallel=True)
def nodal_force_from_stress(tri, b, c, area, h, sigma, scale, ptr, elems, local, out):
    """Nodal force of the internal stress, f_i = −∫ h σ·∇φ_i [N], gathered per
    node through the node→element adjacency (no scatter races).

    ``scale`` (m,) multiplies σ per element. Result added to ``out`` (n, 2).
    """
    n = ptr.shape[0] - 1
    for i in prange(n):
        fx = 0.0
        fy = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            k = local[p]
            w = area[e] * h[e] * scale[e]
            fx -= w * (sigma[e, 0] * b[e, k] + sigma[e, 2] * c[e, k])
            fy -= w * (sigma[e, 2] * b[e, k] + sigma[e, 1] * c[e, k])
        out[i, 0] += fx
        out[i, 1] += fy


@njit(cache=True, parallel=True)
def lumped_mass(ptr, elems, area, rho_h):
    """Lumped nodal mass [kg] = Σ ρ h area / 3 over the elements of each node."""
    n = ptr.shape[0] - 1
    out = np.empty(n)
    for i in prange(n):
        s = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            s += rho_h[e] * area[e]
        out[i] = s / 3.0
    return out


class SparsityPattern:
    """CSR pattern of the 2-dof-per-node P1 stiffness matrix and the map from
    each element's 6×6 block entry to its position in the CSR data array."""

    def __init__(self, tri: np.ndarray, n_nodes: int):
        m = len(tri)
        dofs = np.empty((m, 6), np.int64)
        dofs[:, 0::2] = 2 * tri
        dofs[:, 1::2] = 2 * tri + 1
        rows = np.repeat(dofs, 6, axis=1).ravel()
        cols = np.tile(dofs, (1, 6)).ravel()
        ndof = 2 * n_nodes
        key = rows * ndof + cols
        uniq, inv = np.unique(key, return_inverse=True)
        self.ndof = ndof
        self.nnz = len(uniq)
        r = uniq // ndof
        self.indices = (uniq % ndof).astype(np.int32)
        self.indptr = np.zeros(ndof + 1, np.int32)
        np.cumsum(np.bincount(r, minlength=ndof), out=self.indptr[1:])
        self.entry_map = inv.reshape(m, 36).astype(np.int64)
        self.row_of = r.astype(np.int64)
        self.diag_pos = np.flatnonzero(r == self.indices)
        assert len(self.diag_pos) == ndof
        self._offdiag = None  # positions of the (2i, 2i+1) entries, built on first use

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.ndof, self.ndof))

    def node_offdiag_pos(self):
        """Positions of the (2i, 2i+1) and (2i+1, 2i) entries in the CSR data."""
        if self._offdiag is None:
            ndof = self.ndof
            rows = self.row_of
            cols = self.indices.astype(np.int64)
            key = rows * ndof + cols
            order = np.argsort(key)
            n = ndof // 2
            want01 = (2 * np.arange(n)) * ndof + 2 * np.arange(n) + 1
            want10 = (2 * np.arange(n) + 1) * ndof + 2 * np.arange(n)
            self._offdiag = (order[np.searchsorted(key, want01, sorter=order)],
                             order[np.searchsorted(key, want10, sorter=order)])
        return self._offdiag


@njit(cache=True)
def assemble_elasticity(entry_map, b, c, coef, nu, nnz):
    """Assemble Σ_e coef_e ∫ Bᵀ D B (plane stress, D = K/(1−ν²) in engineering
    shear) into CSR data; ``coef_e = area·h·γ·Δt·E`` [N s m-1 per unit strain rate]."""
    data = np.zeros(nnz)
    d12 = nu
    d33 = 0.5 * (1.0 - nu)
    inv = 1.0 / (1.0 - nu * nu)
    m = b.shape[0]
    for e in range(m):
        w = coef[e] * inv
        for a in range(3):
            ba = b[e, a]
            ca = c[e, a]
            for bb in range(3):
                bj = b[e, bb]
                cj = c[e, bb]
                base = (2 * a) * 6 + 2 * bb
                data[entry_map[e, base]] += w * (ba * bj + d33 * ca * cj)
                data[entry_map[e, base + 1]] += w * (d12 * ba * cj + d33 * ca * bj)
                data[entry_map[e, base + 6]] += w * (d12 * ca * bj + d33 * ba * cj)
                data[entry_map[e, base + 7]] += w * (ca * cj + d33 * ba * bj)
    return data



#: serial builds of the prange kernels above (cheaper on small meshes and on a
#: busy machine; the solvers pick with :func:`lagice._numba.pick`)
shape_gradients_serial = serial_copy(shape_gradients)
strain_rate_serial = serial_copy(strain_rate)
nodal_force_from_stress_serial = serial_copy(nodal_force_from_stress)
lumped_mass_serial = serial_copy(lumped_mass)
SHAPE_GRADIENTS = (shape_gradients_serial, shape_gradients)
STRAIN_RATE = (strain_rate_serial, strain_rate)
NODAL_FORCE = (nodal_force_from_stress_serial, nodal_force_from_stress)
LUMPED_MASS = (lumped_mass_serial, lumped_mass)


# -- the lumped-mass node system ------------------------------------------------------
@njit(cache=True, inline="always")
def solve_node_2x2(a11, a12, a21, a22, rx, ry, fixed_u, fixed_v, pu, pv):
    """New velocity (u, v) of one node from the 2×2 system [[a11, a12], [a21, a22]]
    (u, v) = (rx, ry), with u = pu where ``fixed_u`` or v = pv where ``fixed_v``
    (a prescribed component; callers handle both fixed). 0 for a singular system."""
    if fixed_u:
        return pu, ((ry - a21 * pu) / a22 if a22 != 0.0 else 0.0)
    if fixed_v:
        return ((rx - a12 * pv) / a11 if a11 != 0.0 else 0.0), pv
    det = a11 * a22 - a12 * a21
    if det != 0.0:
        return (a22 * rx - a12 * ry) / det, (a11 * ry - a21 * rx) / det
    return 0.0, 0.0


def _adjacency_weights(tri, b, c, area, h, ptr, elems, local):
    """Per adjacency entry p (node i, element e, local vertex k): w[p] = (area·h·∂φk/∂x,
    area·h·∂φk/∂y) [m² per m], so that the internal force on node i is
    f_i = −Σ_p (w[p, 0] σxx + w[p, 1] σxy, w[p, 0] σxy + w[p, 1] σyy). The two weights
    of an entry sit side by side (one stream for the node kernels to read: +6 % for the
    explicit node kernel on 2 threads against two separate arrays, docs/benchmarks.md)."""
    n = ptr.shape[0] - 1
    w = np.empty((elems.shape[0], 2))
    for i in prange(n):
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            k = local[p]
            a = area[e] * h[e]
            w[p, 0] = a * b[e, k]
            w[p, 1] = a * c[e, k]
    return w


adjacency_weights = njit(cache=True, parallel=True)(_adjacency_weights)
adjacency_weights_serial = serial_copy(_adjacency_weights)
ADJACENCY_WEIGHTS = (adjacency_weights_serial, adjacency_weights)


@dataclass
class NodeSetup:
    """What every sub-step of a lumped-mass stepper needs per node (one outer step).

    h thickness [m] (m,); mass lumped nodal mass [kg]; w (nnz, 2) adjacency weights
    (area·∂φ/∂x, area·∂φ/∂y) per adjacency entry (times h for depth-averaged stress) [m or m²];
    m_dt = m/Δt_sub [kg s-1]; fext = a·τa [N] (n, 2); cda = a·ρw·Cw [kg m-1];
    parallel: whether the parallel kernel builds are used."""

    h: np.ndarray
    mass: np.ndarray
    w: np.ndarray
    m_dt: np.ndarray
    fext: np.ndarray
    cda: np.ndarray
    parallel: bool


class NodeSystem:
    """The lumped-mass node system of a mesh, composed by the sub-stepped steppers
    (explicit Maxwell-EB, mEVP): prescribed degrees of freedom (coast no-slip and
    :class:`~lagice.boundary.VelocityBC`), P1 geometry, lumped mass and adjacency
    weights, and the serial/parallel kernel choice.

    Args:
        mesh: the mesh (node positions read at each :meth:`update_geometry`).
        bcs: list of :class:`~lagice.boundary.VelocityBC`.
        parallel: True/False, or None: parallel kernel builds from
            ``lagice._numba.PARALLEL_MIN_SIZE`` elements up.
        geometry_hook: ``f(node_system)`` called after every geometry update (steppers derive
            their own per-element quantities there).
    """

    def __init__(self, mesh, bcs=(), parallel: bool | None = None, geometry_hook=None):
        self.bcs = list(bcs)
        self.parallel = parallel
        self.geometry_hook = geometry_hook
        self.reset_topology(mesh)

    def reset_topology(self, mesh) -> None:
        """Rebuild everything that depends on connectivity (after a remesh)."""
        self.mesh = mesh
        self.dirichlet = DirichletSet(mesh, self.bcs)
        fixed = np.zeros((mesh.n_nodes, 2), np.int8)
        fixed.reshape(-1)[self.dirichlet.dofs] = 1
        self.fixed = fixed
        self.update_geometry()

    def update_geometry(self) -> None:
        """Shape gradients and areas after nodes moved (Lagrangian step)."""
        m = self.mesh
        self.b, self.c, self.area = SHAPE_GRADIENTS[int(self.parallel_for(m))](m.nodes, m.triangles)
        if np.any(self.area <= 0):
            raise SolverError(f"{int(np.sum(self.area <= 0))} inverted elements in the mesh")
        if self.geometry_hook is not None:
            self.geometry_hook(self)

    def parallel_for(self, mesh=None) -> bool:
        mesh = self.mesh if mesh is None else mesh
        return self.parallel if self.parallel is not None else mesh.n_elements >= PARALLEL_MIN_SIZE

    def prescribed_velocity(self, t_s: float) -> np.ndarray:
        """(n, 2) prescribed velocities at time t [s] (0 where free; see ``self.fixed``)."""
        out = np.zeros((self.mesh.n_nodes, 2))
        if len(self.dirichlet.dofs):
            out.reshape(-1)[self.dirichlet.dofs] = self.dirichlet.values(t_s)
        return out

    def lumped(self, h: np.ndarray, rho: float, par: bool):
        """Lumped nodal mass [kg] and nodal area [m²] for thickness h [m]."""
        lm = LUMPED_MASS[int(par)]
        ptr, elems, _local = self.mesh.node_elements
        return lm(ptr, elems, self.area, rho * h), lm(ptr, elems, self.area, np.ones_like(h))

    def setup(self, thickness, terms, rho: float, dt_sub: float, thickness_weights: bool) -> NodeSetup:
        """Per-node quantities of one outer step from the thickness [m] and the external
        terms ``terms`` (:func:`lagice.forces.explicit_terms`) (see :class:`NodeSetup`)."""
        mesh = self.mesh
        ptr, elems, local = mesh.node_elements
        par = self.parallel_for(mesh)
        h = np.ascontiguousarray(thickness, np.float64)
        mass, node_area = self.lumped(h, rho, par)
        w = ADJACENCY_WEIGHTS[int(par)](mesh.triangles, self.b, self.c, self.area,
                                        h if thickness_weights else np.ones_like(h), ptr, elems, local)
        return NodeSetup(h, mass, w, mass / dt_sub, terms.tau * node_area[:, None],
                         terms.drag_coef * node_area, par)

