"""The triangular mesh: structure of arrays plus derived topology.

A :class:`Mesh` holds node positions (m, projected plane), counter-clockwise
triangles, boundary edges with tags, and the node→element adjacency (CSR)
that the node kernels gather through so that parallel loops never race.

Boundary tags: tag names are free strings. Two names are special:

* ``"coast"``: no-slip, nodes fixed (velocity 0, position fixed);
* ``"open"``: traction-free, ice may leave the domain.

Any other name is a *named segment* on which a velocity may be prescribed per
component (e.g. ``"top"`` in the uniaxial compression scene). An edge without a
prescribed condition is traction-free.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..errors import ConfigError, MeshError

COAST = "coast"
OPEN = "open"


@njit(cache=True)
def _signed_areas_kernel(nodes, tri, out):
    for e in range(tri.shape[0]):
        i, j, k = tri[e, 0], tri[e, 1], tri[e, 2]
        out[e] = 0.5 * ((nodes[j, 0] - nodes[i, 0]) * (nodes[k, 1] - nodes[i, 1])
                        - (nodes[k, 0] - nodes[i, 0]) * (nodes[j, 1] - nodes[i, 1]))


def signed_areas(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Signed triangle areas [m²]; positive for counter-clockwise triangles (a compiled loop:
    the numpy gathers took ~1 ms at 26k elements, and this runs every step)."""
    triangles = np.asarray(triangles)
    out = np.empty(len(triangles))
    if len(triangles):
        _signed_areas_kernel(np.ascontiguousarray(nodes, np.float64),
                             np.ascontiguousarray(triangles.reshape(-1, 3)), out)
    return out


@njit(cache=True)
def _centroids_kernel(nodes, tri, out):
    """(a + b + c)/3 per coordinate, in numpy's ``nodes[tri].mean(axis=1)`` order (bit for bit):
    that numpy expression costs ~3 ms at 26k elements (a gathered (m, 3, 2) copy and a
    strided reduction) and ran several times per step; this loop ~0.1 ms."""
    for e in range(tri.shape[0]):
        i, j, k = tri[e, 0], tri[e, 1], tri[e, 2]
        out[e, 0] = (nodes[i, 0] + nodes[j, 0] + nodes[k, 0]) / 3.0
        out[e, 1] = (nodes[i, 1] + nodes[j, 1] + nodes[k, 1]) / 3.0


def centroids(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 2) element centroids [m]."""
    out = np.empty((len(triangles), 2))
    if len(triangles):
        _centroids_kernel(np.ascontiguousarray(nodes, np.float64), np.ascontiguousarray(triangles), out)
    return out


def node_element_adjacency(triangles: np.ndarray, n_nodes: int):
    """CSR adjacency node → (element, local vertex index).

    Returns ``ptr`` (n_nodes+1,), ``elements`` and ``local`` (3 m,), so that
    the elements around node ``i`` are ``elements[ptr[i]:ptr[i+1]]`` and node
    ``i`` is vertex ``local[k]`` of element ``elements[k]``.
    """
    flat = triangles.ravel()
    order = np.argsort(flat, kind="stable")
    counts = np.bincount(flat, minlength=n_nodes)
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(counts, out=ptr[1:])
    elements = (order // 3).astype(np.int64)
    local = (order % 3).astype(np.int64)
    return ptr, elements, local


def boundary_edges_of(triangles: np.ndarray) -> np.ndarray:
    """Edges that belong to exactly one triangle, oriented as in that triangle
    (so the domain lies to their left)."""
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    key = np.sort(e, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return e[cnt[inv.ravel()] == 1]


@dataclass
class Mesh:
    """Triangular mesh (P1 nodes, P0 elements).

    Attributes:
        nodes: (n, 2) float64 node positions [m].
        triangles: (m, 3) int64 node indices, counter-clockwise.
        boundary_edges: (k, 2) int64 node pairs, domain on the left.
        boundary_tags: (k,) int32 index into ``tag_names``.
        tag_names: tuple of tag names (``"coast"``, ``"open"`` or a segment name).
    """

    nodes: np.ndarray
    triangles: np.ndarray
    boundary_edges: np.ndarray
    boundary_tags: np.ndarray
    tag_names: tuple
    _adj: tuple | None = field(default=None, repr=False)
    _fixed: np.ndarray | None = field(default=None, repr=False)
    _edge_on_boundary: np.ndarray | None = field(default=None, repr=False)
    #: caches of other modules keyed on this mesh's topology (name -> value); cleared by nothing,
    #: since a mesh's triangles and boundary never change (a remesh makes a new Mesh)
    _topology_cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        self.nodes = np.ascontiguousarray(self.nodes, dtype=np.float64)
        self.triangles = np.ascontiguousarray(self.triangles, dtype=np.int64)
        self.boundary_edges = np.ascontiguousarray(self.boundary_edges, dtype=np.int64).reshape(-1, 2)
        self.boundary_tags = np.ascontiguousarray(self.boundary_tags, dtype=np.int32)
        self.tag_names = tuple(self.tag_names)
        if self.nodes.ndim != 2 or self.nodes.shape[1] != 2:
            raise MeshError(f"nodes must have shape (n, 2); got {self.nodes.shape}")
        if self.triangles.ndim != 2 or self.triangles.shape[1] != 3:
            raise MeshError(f"triangles must have shape (m, 3); got {self.triangles.shape}")
        if len(self.triangles) and (self.triangles.min() < 0 or self.triangles.max() >= len(self.nodes)):
            raise MeshError("triangles reference nodes outside 0..n_nodes-1")
        if self.boundary_tags.shape != (len(self.boundary_edges),):
            raise MeshError("boundary_tags must have one entry per boundary edge")

    # -- sizes -----------------------------------------------------------
    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_elements(self) -> int:
        return len(self.triangles)

    def areas(self, nodes: np.ndarray | None = None) -> np.ndarray:
        """Signed element areas [m²] for the given (or current) node positions."""
        return signed_areas(self.nodes if nodes is None else nodes, self.triangles)

    def element_size(self) -> np.ndarray:
        """Element size Δx [m] = sqrt(2·area) (leg of the equivalent right isoceles triangle)."""
        return np.sqrt(2.0 * np.abs(self.areas()))

    def centroids(self) -> np.ndarray:
        """(m, 2) element centroids [m] (a new array)."""
        return centroids(self.nodes, self.triangles)

    # -- topology --------------------------------------------------------
    @property
    def node_elements(self):
        """(ptr, elements, local): node→element CSR adjacency (cached)."""
        if self._adj is None:
            self._adj = node_element_adjacency(self.triangles, self.n_nodes)
        return self._adj

    def tag_id(self, name: str) -> int:
        try:
            return self.tag_names.index(name)
        except ValueError:
            raise ConfigError(
                f"unknown boundary tag {name!r}; this mesh has tags {list(self.tag_names)}") from None

    def edges_with_tag(self, name: str) -> np.ndarray:
        return self.boundary_edges[self.boundary_tags == self.tag_id(name)]

    def nodes_with_tag(self, name: str) -> np.ndarray:
        """Sorted unique node indices on edges tagged ``name``."""
        return np.unique(self.edges_with_tag(name))

    def has_tag(self, name: str) -> bool:
        return name in self.tag_names

    @property
    def fixed_node_mask(self) -> np.ndarray:
        """(n,) bool, cached: nodes on ``"coast"`` or ``"open"`` edges (they never
        move with the ice; the tags of a mesh do not change, its node positions may)."""
        if self._fixed is None:
            fixed = np.zeros(self.n_nodes, dtype=bool)
            for name in (COAST, OPEN):
                if self.has_tag(name):
                    fixed[self.nodes_with_tag(name)] = True
            self._fixed = fixed
        return self._fixed

    @property
    def edge_on_boundary(self) -> np.ndarray:
        """(m, 3) bool, cached: edge k (opposite vertex k) of each element lies on the
        domain boundary (the topology does not change while nodes move)."""
        if self._edge_on_boundary is None:
            n = np.int64(self.n_nodes)
            be = self.boundary_edges
            keys = np.sort(np.minimum(be[:, 0], be[:, 1]) * n + np.maximum(be[:, 0], be[:, 1]))
            tri = self.triangles
            out = np.zeros(tri.shape, dtype=bool)
            for k in range(3):
                a, b = tri[:, (k + 1) % 3], tri[:, (k + 2) % 3]
                q = np.minimum(a, b) * n + np.maximum(a, b)
                pos = np.minimum(np.searchsorted(keys, q), max(len(keys) - 1, 0))
                out[:, k] = (keys[pos] == q) if len(keys) else False
            self._edge_on_boundary = out
        return self._edge_on_boundary

    def coast_nodes(self) -> np.ndarray:
        return self.nodes_with_tag(COAST) if self.has_tag(COAST) else np.zeros(0, np.int64)

    def copy(self) -> Mesh:
        return Mesh(self.nodes.copy(), self.triangles.copy(), self.boundary_edges.copy(),
                    self.boundary_tags.copy(), self.tag_names)

    def check(self) -> None:
        """Raise :class:`MeshError` if any triangle is not counter-clockwise."""
        a = self.areas()
        if np.any(a <= 0):
            bad = np.flatnonzero(a <= 0)
            raise MeshError(f"{len(bad)} triangles have non-positive area (first: element {bad[0]}, "
                            f"area {a[bad[0]]:.3g} m²)")
