"""Crouzeix–Raviart velocities for the explicit stepper (``solver.velocity_element =
"crouzeix_raviart"``; docs/solvers.md, "Volumetric locking").

The velocity is linear in each triangle and continuous only at the edge midpoints, where
its degrees of freedom sit (Crouzeix and Raviart 1973, "Conforming and nonconforming finite
element methods for solving the stationary Stokes equations I", RAIRO Anal. Numér. 7). The
basis function of the edge opposite local vertex k is ψ_k = 1 − 2 φ_k (φ_k the linear
hat of vertex k), so ∇ψ_k = −2 ∇φ_k, and its mass matrix is diagonal: ∫ψ_j ψ_k = δ_jk A/3,
exactly. Stress, damage and every element field stay constant per element, as before.

Why: with one stress per linear triangle, ice whose mean stress is kept while its deviator
relaxes is locked by the mesh (no non-zero velocity has zero divergence in every element,
:func:`lagice.solvers.explicit._node_divergence`). The Crouzeix–Raviart velocity with one
pressure per element is the classic stable pair for incompressible flow: on a closed mesh its
element divergences have rank m − 1 (only the constant pressure is free) and a discrete
inf–sup constant independent of the element size (``tests/test_crouzeix_raviart.py``).

The stepper's kernels need nothing new: the "node" kernels of
:mod:`lagice.solvers.explicit` loop over any entity with an entity→element adjacency, so they
are given the edges, with the weights −2 area h ∇φ_k, and the element kernel is given the
element→edge table with −2 ∇φ. What this module adds is that bookkeeping: the edges, their
adjacency, their prescribed components, and the transfer of velocities between the nodes
(where the mesh moves, checkpoints are written and remeshing interpolates) and the edges.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from .._numba import serial_copy

#: how many times shorter than the measured linear limit the sub-step is: the highest frequency² of
#: the lumped Crouzeix–Raviart system is 5.1–6.4 times the linear one's on gmsh Delaunay boxes at 6
#: and 10 km (same modulus and thickness), 6.5 and 7.4 times with the jump penalty at κ = 0.1 and 1
#: (``tests/test_crouzeix_raviart.py`` checks that these stay below this factor squared, 9). The first
#: screens (2026-11-28 20:06 UTC) ran with 2.5, before the ratio was measured with the elastic
#: matrix of the plane-stress modulus (6.4 > 2.5² = 6.25 at 10 km, inside the safety factor's margin)
SUBSTEP_FACTOR = 3.0


class CREdges:
    """The edges of a mesh as Crouzeix–Raviart degrees of freedom.

    Attributes:
        nodes: (E, 2) int64 end nodes of each edge (sorted).
        elem_edges: (m, 3) int32, the edge opposite local vertex k of each element.
        ptr, elems, local: the edge→element adjacency (CSR, int32 for the kernels; local is k).
        fixed: (E, 2) int8, prescribed components: a boundary edge (one element) both of whose
            end nodes are prescribed in that component.
    """

    def __init__(self, mesh, node_fixed: np.ndarray):
        tri = np.asarray(mesh.triangles, np.int64)
        n, m = mesh.n_nodes, len(tri)
        a = np.stack([tri[:, 1], tri[:, 2], tri[:, 0]], axis=1)  # edge k joins vertices k+1, k+2
        b = np.stack([tri[:, 2], tri[:, 0], tri[:, 1]], axis=1)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        keys, inv = np.unique((lo * n + hi).ravel(), return_inverse=True)
        self.nodes = np.stack([keys // n, keys % n], axis=1)
        self.elem_edges = inv.reshape(m, 3).astype(np.int32)
        n_e = len(keys)
        order = np.argsort(inv, kind="stable")
        counts = np.bincount(inv, minlength=n_e)
        self.ptr = np.zeros(n_e + 1, np.int32)
        np.cumsum(counts, out=self.ptr[1:])
        self.elems = (order // 3).astype(np.int32)
        self.local = (order % 3).astype(np.int32)
        boundary = counts == 1
        nf = np.asarray(node_fixed, np.int8)
        both = nf[self.nodes[:, 0]] & nf[self.nodes[:, 1]]
        self.fixed = (both * boundary[:, None]).astype(np.int8)

    @property
    def n_edges(self) -> int:
        return len(self.nodes)

    def at_edges(self, node_values: np.ndarray) -> np.ndarray:
        """Edge values (E, k) of a node field (n, k): the mean of the two end nodes (exact for a
        field linear along the edge, so a linear velocity field is reproduced exactly)."""
        return 0.5 * (node_values[self.nodes[:, 0]] + node_values[self.nodes[:, 1]])

    def midpoints(self, xy: np.ndarray) -> np.ndarray:
        """Edge midpoints (E, 2) [m] of node positions (n, 2)."""
        return self.at_edges(xy)

    def at_nodes(self, edge_vel: np.ndarray, tri: np.ndarray, area: np.ndarray, n: int) -> np.ndarray:
        """Node velocities (n, 2) from edge velocities (E, 2): the area-weighted mean, over the
        elements around each node, of each element's linear field at that vertex,
        u(x_k) = u_(k+1) + u_(k+2) − u_k (ψ_j(x_k) = 1 − 2δ_jk). A linear field is reproduced
        exactly (a test checks it)."""
        ee = self.elem_edges
        u = edge_vel[ee]  # (m, 3, 2)
        tot = u.sum(axis=1)  # (m, 2)
        out = np.zeros((n, 2))
        wsum = np.bincount(tri.ravel(), weights=np.repeat(area, 3), minlength=n)
        for k in range(3):
            vk = tot - 2.0 * u[:, k, :]
            for j in range(2):
                out[:, j] += np.bincount(tri[:, k], weights=area * vk[:, j], minlength=n)
        return out / wsum[:, None]


# -- the jump penalty (solver.jump_penalty) ------------------------------------------------
class JumpPenalty:
    """The interior-edge jump penalty of Hansbo and Larson (2003, "Discontinuous Galerkin and
    the Crouzeix–Raviart element: application to elasticity", ESAIM: M2AN 37) for the
    Crouzeix–Raviart velocities: (2μκ/h_e) ∫_e [u]·[v] ds over every interior edge e. The plain
    element fails the discrete Korn inequality (Falk 1991, "Nonconforming finite element methods
    for the equations of linear elasticity", Math. Comp. 57): on the 10 km Delaunay box its softest
    mode is 500x softer than the linear element's. The penalty takes it back to the linear
    element's (κ ≥ 0.1, ``tests/test_crouzeix_raviart.py``) and, scaled by the shear modulus μ and
    not the bulk modulus, does not lock (Hansbo and Larson).

    With the velocity linear on each side, the jump along an edge of length L is [u](s) = J s,
    J the jump of the tangential derivative ∂u/∂t (s from −L/2 to L/2), so the penalty's energy is
    ½ k |J|² with k = μ κ h L²/6 (h the ice thickness, μ = E/(2(1 + ν)), both the mean of the two
    elements). In the Maxwell-EB stepper it is carried as a traction T = k J [N m] per interior
    edge, updated like the element stress, T ← (T + Δt_s k J̇) γ̄ (γ̄ the mean relaxation factor
    of the two elements: the penalty relaxes as the deviator does), and its force on edge
    velocity q is −Σ T ∂J/∂u_q.

    Attributes (per interior edge p): dofs (P, 6) int32, the three edges of each of its two
    elements; coef (P, 6) ∂J/∂u [m-1] (+ for the first element, − for the second); left, right
    (P,) int32 the two elements; kfac (P,) κ L²/(12(1 + ν)) [m²], so that Δt_s k = kfac h̄ Δt_s Ē;
    and the gather by edge velocity (ptr, idx, c): for each edge q the (p, ∂J_p/∂u_q) entries.
    """

    def __init__(self, cr: CREdges, kappa: float, poisson: float):
        self.cr = cr
        self.kappa = float(kappa)
        self.poisson = float(poisson)
        inner = np.flatnonzero(np.diff(cr.ptr) == 2)
        self.inner = inner
        self.left = cr.elems[cr.ptr[inner]].astype(np.int32)
        self.right = cr.elems[cr.ptr[inner] + 1].astype(np.int32)
        self.dofs = np.ascontiguousarray(np.concatenate([cr.elem_edges[self.left], cr.elem_edges[self.right]],
                                                        axis=1), np.int32)
        flat = self.dofs.ravel()
        order = np.argsort(flat, kind="stable")
        counts = np.bincount(flat, minlength=cr.n_edges)
        self.ptr = np.zeros(cr.n_edges + 1, np.int32)
        np.cumsum(counts, out=self.ptr[1:])
        self._order = order
        self.idx = (order // 6).astype(np.int32)
        self.coef = None
        self.c = None
        self.kfac = None

    def update_geometry(self, nodes: np.ndarray, b: np.ndarray, c: np.ndarray) -> None:
        """∂J/∂u and the stiffness factors after the nodes moved (b, c: the linear ∂φ/∂x, ∂φ/∂y)."""
        ends = self.cr.nodes[self.inner]
        t = nodes[ends[:, 1]] - nodes[ends[:, 0]]
        L2 = np.einsum("ij,ij->i", t, t)
        t = t / np.sqrt(L2)[:, None]
        coef = np.empty((len(self.inner), 6))
        for side, (el, sign) in enumerate(((self.left, 1.0), (self.right, -1.0))):
            # ∇ψ_k · t = −2 ∇φ_k · t
            coef[:, 3 * side:3 * side + 3] = sign * -2.0 * (b[el] * t[:, :1] + c[el] * t[:, 1:])
        self.coef = coef
        self.c = np.ascontiguousarray(coef.ravel()[self._order])
        self.kfac = self.kappa * L2 / (12.0 * (1.0 + self.poisson))

    @property
    def n_inner(self) -> int:
        return len(self.inner)


def _jump_update(vel, dofs, coef, left, right, h, e_dt, gamma, kfac, T):
    """T ← (T + Δt_s k J̇) γ̄ on every interior edge (:class:`JumpPenalty`), from the edge
    velocities ``vel`` (E, 2), thickness h [m] and the element kernel's e_dt = Δt_s E [Pa s] and γ."""
    for p in prange(dofs.shape[0]):
        jx = 0.0
        jy = 0.0
        for s in range(6):
            q = dofs[p, s]
            a = coef[p, s]
            jx += a * vel[q, 0]
            jy += a * vel[q, 1]
        lt = left[p]
        rt = right[p]
        kdt = kfac[p] * 0.5 * (h[lt] * e_dt[lt] + h[rt] * e_dt[rt])
        g = 0.5 * (gamma[lt] + gamma[rt])
        T[p, 0] = (T[p, 0] + kdt * jx) * g
        T[p, 1] = (T[p, 1] + kdt * jy) * g


def _jump_impulse(vel, fixed, ptr, idx, c, T, dt_over_m):
    """u_q += Δt_s/m_q · (−Σ_p T_p ∂J_p/∂u_q) on the free components of every edge velocity:
    the penalty's force, explicit, before the sub-step's momentum update."""
    for q in prange(ptr.shape[0] - 1):
        fx = 0.0
        fy = 0.0
        for k in range(ptr[q], ptr[q + 1]):
            p = idx[k]
            a = c[k]
            fx -= a * T[p, 0]
            fy -= a * T[p, 1]
        if not fixed[q, 0]:
            vel[q, 0] += fx * dt_over_m[q]
        if not fixed[q, 1]:
            vel[q, 1] += fy * dt_over_m[q]


jump_update_kernel = njit(cache=True, parallel=True, error_model="numpy")(_jump_update)
jump_update_kernel_serial = serial_copy(_jump_update, error_model="numpy")
jump_impulse_kernel = njit(cache=True, parallel=True, error_model="numpy")(_jump_impulse)
jump_impulse_kernel_serial = serial_copy(_jump_impulse, error_model="numpy")
