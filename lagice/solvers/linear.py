"""Sparse linear solvers for the implicit step, chosen by measurement
(``benchmarks/bench_implicit.py``): SuperLU (with factor reuse while the
matrix is unchanged), Jacobi-preconditioned warm-started CG (a numba kernel:
scipy's ``cg`` costs tens of microseconds of Python per iteration), and pyamg
smoothed aggregation with rigid-body modes as a CG preconditioner."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from ..errors import ConfigError, SolverError

LINEAR_SOLVERS = ("cg", "superlu", "amg")


class LinearSolver:
    def __init__(self, kind: str = "cg", rtol: float = 1e-10, maxiter: int = 2000):
        if kind not in LINEAR_SOLVERS:
            raise ConfigError(f"linear_solver = {kind!r} is unknown; expected one of {LINEAR_SOLVERS}")
        self.kind = kind
        self.rtol = rtol
        self.maxiter = maxiter
        self._data_key = None
        self._lu = None
        self._amg = None
        self.last_iterations = 0
        self.nodes = None  # for rigid-body modes (amg)

    def _changed(self, A) -> bool:
        key = self._data_key
        if key is not None and key.shape == A.data.shape and np.array_equal(key, A.data):
            return False
        self._data_key = A.data.copy()
        return True

    def solve(self, A: sp.csr_matrix, b: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
        if self.kind == "superlu":
            if self._changed(A) or self._lu is None:
                self._lu = spla.splu(A.tocsc(), permc_spec="COLAMD")
            self.last_iterations = 1
            x = self._lu.solve(b)
        else:
            count = [0]

            def cb(_xk):
                count[0] += 1

            if self.kind == "cg":
                x = np.array(b if x0 is None else x0, dtype=np.float64, copy=True)
                its, _res = jacobi_pcg(A.indptr, A.indices, A.data, b, x, self.rtol, self.maxiter)
                if its < 0:
                    raise SolverError(f"cg did not converge to rtol={self.rtol:g} in {self.maxiter} iterations")
                self.last_iterations = its
                if not np.all(np.isfinite(x)):
                    raise SolverError("linear solver cg returned NaN/inf")
                return x
            else:
                if self._changed(A) or self._amg is None:
                    import pyamg
                    B = _rigid_body_modes(self.nodes, A.shape[0])
                    self._amg = pyamg.smoothed_aggregation_solver(A, B=B, max_coarse=200)
                M = self._amg.aspreconditioner(cycle="V")
            x, info = spla.cg(A, b, x0=x0, rtol=self.rtol, atol=0.0, maxiter=self.maxiter, M=M,
                              callback=cb)
            self.last_iterations = count[0]
            if info != 0:
                raise SolverError(f"{self.kind} did not converge to rtol={self.rtol:g} in "
                                  f"{self.maxiter} iterations (info={info})")
        if not np.all(np.isfinite(x)):
            raise SolverError(f"linear solver {self.kind} returned NaN/inf")
        return x


def _rigid_body_modes(nodes, ndof):
    B = np.zeros((ndof, 3))
    B[0::2, 0] = 1.0
    B[1::2, 1] = 1.0
    if nodes is not None:
        xc = nodes - nodes.mean(axis=0)
        scale = max(np.abs(xc).max(), 1.0)
        B[0::2, 2] = -xc[:, 1] / scale
        B[1::2, 2] = xc[:, 0] / scale
    return B


@njit(cache=True)
def _csr_matvec(indptr, indices, data, x, out):
    for i in range(indptr.shape[0] - 1):
        s = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            s += data[p] * x[indices[p]]
        out[i] = s


@njit(cache=True)
def jacobi_pcg(indptr, indices, data, b, x, rtol, maxiter):
    """Jacobi-preconditioned conjugate gradients on a CSR matrix, in place on x.

    Stops when ‖b − A x‖ ≤ rtol ‖b‖ (same criterion as scipy's ``cg`` with
    atol = 0). Returns (iterations, final residual norm); iterations = −1 if
    ``maxiter`` was reached.
    """
    n = b.shape[0]
    dinv = np.empty(n)
    for i in range(n):
        d = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            if indices[p] == i:
                d = data[p]
        dinv[i] = 1.0 / d
    r = np.empty(n)
    _csr_matvec(indptr, indices, data, x, r)
    bnorm = 0.0
    for i in range(n):
        r[i] = b[i] - r[i]
        bnorm += b[i] * b[i]
    bnorm = np.sqrt(bnorm)
    tol = rtol * bnorm
    z = r * dinv
    p = z.copy()
    rz = np.dot(r, z)
    q = np.empty(n)
    rnorm = np.sqrt(np.dot(r, r))
    if rnorm <= tol:
        return 0, rnorm
    for it in range(1, maxiter + 1):
        _csr_matvec(indptr, indices, data, p, q)
        alpha = rz / np.dot(p, q)
        rr = 0.0
        for i in range(n):
            x[i] += alpha * p[i]
            r[i] -= alpha * q[i]
            rr += r[i] * r[i]
        rnorm = np.sqrt(rr)
        if rnorm <= tol:
            return it, rnorm
        rz_new = 0.0
        for i in range(n):
            z[i] = r[i] * dinv[i]
            rz_new += r[i] * z[i]
        beta = rz_new / rz
        rz = rz_new
        for i in range(n):
            p[i] = z[i] + beta * p[i]
    return -1, rnorm
