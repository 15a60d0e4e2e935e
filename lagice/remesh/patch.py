"""Local remeshing with gmsh (docs/design.md §5).

A *patch* is a set of elements: the bad elements plus ``rings`` rings of
neighbours (elements sharing a node), grown further where the patch would
pinch at a vertex so that its boundary is a set of simple closed loops.
The patch boundary (outer loops and holes, one component per connected part)
is handed to gmsh with the boundary nodes as points and the boundary edges as
lines that are transfinite with 2 nodes, so gmsh puts **no** new node on the
patch boundary; the interior is meshed following the target size field
(fixed in space). The new triangles are stitched in place of the old patch:

* nodes: old nodes not removed keep their order, new interior nodes are appended;
* elements: elements outside the patch keep their order, the new patch
  elements are appended (``Stitch.kept_elements`` maps new → old index);
* boundary edges and tags of the domain are unchanged (the patch boundary,
  which contains any domain boundary edge of a patch element, is reused).

A global remesh is the patch made of all elements: the domain boundary
nodes (coast and every other tag) stay where they are.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MeshError
from ..mesh import Mesh, gmsh_session, signed_areas
from ..mesh.generate import set_size_options
from .trigger import evaluate_size


@dataclass
class PatchBoundary:
    """Boundary of a patch: directed edges (patch on the left) grouped into loops."""

    loops: list          # list of (k,) int64 arrays of node indices (closed, not repeated)
    outer: list          # bool per loop: counter-clockwise (outer) or clockwise (hole)
    components: list     # list of (outer loop index, [hole loop indices])


def grow_patch(mesh: Mesh, seed_mask: np.ndarray, rings: int) -> np.ndarray:
    """Element mask: ``seed_mask`` plus ``rings`` rings of node-sharing neighbours."""
    mask = np.asarray(seed_mask, bool).copy()
    for _ in range(int(rings)):
        mark = np.zeros(mesh.n_nodes, bool)
        mark[mesh.triangles[mask].ravel()] = True
        mask |= mark[mesh.triangles].any(axis=1)
    return mask


def _elements_of_nodes(mesh: Mesh, nodes: np.ndarray) -> np.ndarray:
    mark = np.zeros(mesh.n_nodes, bool)
    mark[nodes] = True
    return mark[mesh.triangles].any(axis=1)


def _patch_edges(tri_p: np.ndarray, n_nodes: int):
    """Directed boundary edges of a set of triangles (each appears once undirected)."""
    e = np.concatenate([tri_p[:, [0, 1]], tri_p[:, [1, 2]], tri_p[:, [2, 0]]])
    n = np.int64(n_nodes)
    key = np.minimum(e[:, 0], e[:, 1]) * n + np.maximum(e[:, 0], e[:, 1])
    _, inv, cnt = np.unique(key, return_inverse=True, return_counts=True)
    return e[cnt[inv.ravel()] == 1]


def make_manifold(mesh: Mesh, mask: np.ndarray, max_iter: int = 50) -> np.ndarray:
    """Grow ``mask`` until no patch-boundary vertex has more than one outgoing
    boundary edge (the patch boundary is then a set of simple loops)."""
    mask = mask.copy()
    for _ in range(max_iter):
        be = _patch_edges(mesh.triangles[mask], mesh.n_nodes)
        cnt = np.bincount(be[:, 0], minlength=mesh.n_nodes)
        pinch = np.flatnonzero(cnt > 1)
        if len(pinch) == 0:
            return mask
        mask |= _elements_of_nodes(mesh, pinch)
    raise MeshError("could not make the remesh patch boundary manifold")


def patch_boundary(mesh: Mesh, mask: np.ndarray) -> PatchBoundary:
    """Loops of the patch boundary, classified into outer loops and holes."""
    import shapely

    be = _patch_edges(mesh.triangles[mask], mesh.n_nodes)
    nxt = {}
    for a, b in be.tolist():
        if a in nxt:
            raise MeshError(f"patch boundary is not manifold at node {a}")
        nxt[a] = b
    loops, seen = [], set()
    for a, _ in be.tolist():
        if a in seen:
            continue
        loop = [a]
        seen.add(a)
        c = nxt[a]
        while c != a:
            if c in seen or c not in nxt:
                raise MeshError(f"patch boundary loop through node {c} is not simple")
            loop.append(c)
            seen.add(c)
            c = nxt[c]
        loops.append(np.array(loop, np.int64))
    outer = []
    for lp in loops:
        p = mesh.nodes[lp]
        a2 = np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
        outer.append(bool(a2 > 0))
    comps = [[k, []] for k in range(len(loops)) if outer[k]]
    polys = [shapely.Polygon(mesh.nodes[loops[k]]) for k, _ in comps]
    for k in range(len(loops)):
        if outer[k]:
            continue
        pt = shapely.Point(mesh.nodes[loops[k][0]])
        inside = [c for c, poly in enumerate(polys) if poly.contains(pt)]
        if not inside:
            raise MeshError("a hole of the remesh patch lies in no outer loop")
        # innermost containing outer loop (smallest area)
        c = min(inside, key=lambda c: polys[c].area)
        comps[c][1].append(k)
    return PatchBoundary(loops, outer, [(a, h) for a, h in comps])


#: area per element over the square of its target size h, per gmsh algorithm
#: (:func:`element_area_per_size2`)
_AREA_PER_SIZE2: dict = {}


def element_area_per_size2(algorithm: int) -> float:
    """Mean element area / h² of a mesh that gmsh ``algorithm`` makes at a uniform target size h:
    the density a remeshed patch should have (``density_control``). Measured once per algorithm
    and process on a 24 h × 24 h square (about 1 300 elements, some 20 ms): an equilateral
    mesh has √3/4 = 0.433; gmsh's Frontal-Delaunay (6) gives about 0.43, its Delaunay (5) about
    0.38 (it makes edges a little shorter than h)."""
    algorithm = int(algorithm)
    if algorithm not in _AREA_PER_SIZE2:
        n = 24
        with gmsh_session("lagice_density") as gmsh:
            geo = gmsh.model.geo
            pts = [geo.addPoint(x, y, 0.0, 1.0) for x, y in ((0, 0), (n, 0), (n, n), (0, n))]
            lines = [geo.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
            geo.addPlaneSurface([geo.addCurveLoop(lines)])
            geo.synchronize()
            for ln in lines:
                gmsh.model.mesh.setTransfiniteCurve(ln, n + 1)
            set_size_options(gmsh, algorithm, 1.0)
            gmsh.model.mesh.generate(2)
            etypes, _, enodes = gmsh.model.mesh.getElements(2)
        n_tri = len(enodes[list(etypes).index(2)]) // 3
        _AREA_PER_SIZE2[algorithm] = float(n * n) / n_tri
    return _AREA_PER_SIZE2[algorithm]


def _area_over_size2(mesh: Mesh, size_field, elements=None) -> np.ndarray:
    """A_e / h(c_e)² of ``elements`` (all by default), c_e the centroid."""
    tri = mesh.triangles if elements is None else mesh.triangles[elements]
    c = mesh.nodes[tri].mean(axis=1)
    h = evaluate_size(size_field, c[:, 0], c[:, 1])
    return np.abs(signed_areas(mesh.nodes, tri)) / h ** 2


def area_per_size2(mesh: Mesh, size_field, elements=None) -> float:
    """Mean of A_e / h(c_e)² over ``elements`` (all by default) of ``mesh``: its density
    relative to the target size (c_e the centroid)."""
    return float(np.mean(_area_over_size2(mesh, size_field, elements)))


def target_element_count(mesh: Mesh, elements: np.ndarray, size_field, algorithm: int,
                         reference: float | None = None) -> float:
    """How many elements the area of ``elements`` holds at the reference density: Σ A_e /
    (k h(c_e)²), c_e the centroid, k = ``reference`` (area per element / h²; the Remesher
    passes the mesh's own at the start of the run) or, by default, what gmsh ``algorithm``
    gives inside a large region (:func:`element_area_per_size2`)."""
    k = element_area_per_size2(algorithm) if reference is None else float(reference)
    return float(np.sum(_area_over_size2(mesh, size_field, elements)) / k)


def mesh_patch(mesh: Mesh, bnd: PatchBoundary, size_field, algorithm: int = 6, size_scale: float = 1.0):
    """Mesh the patch with gmsh, keeping its boundary nodes exactly.

    ``size_scale`` multiplies the target size inside the patch (``density_control``).
    Returns ``(new_nodes (q, 2), tri (t, 3))`` where ``tri`` indexes the old
    mesh's node numbers for boundary nodes and ``n_old + k`` for new node ``k``.
    """
    if size_scale != 1.0:
        base, scale = size_field, float(size_scale)
        size_field = (lambda x, y: scale * evaluate_size(base, x, y)) if callable(base) else scale * float(base)
    bnodes = np.unique(np.concatenate(bnd.loops))
    xy = mesh.nodes[bnodes]
    const = not callable(size_field)
    with gmsh_session("lagice_patch") as gmsh:
        geo = gmsh.model.geo
        lc = evaluate_size(size_field, xy[:, 0], xy[:, 1])
        ptag = {}
        for k, v in enumerate(bnodes.tolist()):
            ptag[v] = geo.addPoint(float(xy[k, 0]), float(xy[k, 1]), 0.0, float(lc[k]))
        loop_tags = []
        lines_all = []
        for lp in bnd.loops:
            lp = lp.tolist()
            lines = [geo.addLine(ptag[lp[i]], ptag[lp[(i + 1) % len(lp)]]) for i in range(len(lp))]
            lines_all += lines
            loop_tags.append(geo.addCurveLoop(lines, reorient=False))
        for o, holes in bnd.components:
            geo.addPlaneSurface([loop_tags[o]] + [loop_tags[h] for h in holes])
        geo.synchronize()
        for ln in lines_all:
            gmsh.model.mesh.setTransfiniteCurve(ln, 2)
        set_size_options(gmsh, algorithm, float(size_field) if const else 1e22)
        if not const:
            def cb(dim, tag, x, y, z, lc_):
                return float(evaluate_size(size_field, np.array([x]), np.array([y]))[0])

            gmsh.model.mesh.setSizeCallback(cb)
        try:
            gmsh.model.mesh.generate(2)
        except Exception as exc:  # noqa: BLE001 - gmsh raises bare Exception
            raise MeshError(f"gmsh failed to mesh a remesh patch: {exc}") from exc
        finally:
            if not const:
                gmsh.model.mesh.removeSizeCallback()
        tags, coords, _ = gmsh.model.mesh.getNodes()
        tags1, _, _ = gmsh.model.mesh.getNodes(1, -1, includeBoundary=False)
        etypes, _, enodes = gmsh.model.mesh.getElements(2)
    if len(tags1):
        raise MeshError(f"gmsh put {len(tags1)} nodes on the patch boundary")
    etypes = list(etypes)
    if 2 not in etypes:
        raise MeshError("gmsh produced no triangles for a remesh patch")
    tri_g = np.asarray(enodes[etypes.index(2)], np.int64).reshape(-1, 3)
    if any(t != 2 for t in etypes):
        raise MeshError(f"gmsh produced non-triangle elements {etypes}")
    tags = np.asarray(tags, np.int64)
    coords = np.asarray(coords).reshape(-1, 3)[:, :2]
    # map gmsh nodes to old boundary nodes by exact coordinates
    key_old = {(float(x), float(y)): int(v) for (x, y), v in zip(xy, bnodes)}
    gmap = np.full(int(tags.max()) + 1, -1, np.int64)
    is_new = np.ones(len(tags), bool)
    for k in range(len(tags)):
        v = key_old.get((float(coords[k, 0]), float(coords[k, 1])))
        if v is not None:
            gmap[tags[k]] = v
            is_new[k] = False
    if (~is_new).sum() != len(bnodes):
        raise MeshError("gmsh moved patch boundary nodes")
    used = np.zeros(len(gmap), bool)
    used[tri_g.ravel()] = True
    new_k = np.flatnonzero(is_new & used[tags])
    # deterministic order of new nodes: gmsh tag order
    gmap[tags[new_k]] = mesh.n_nodes + np.arange(len(new_k))
    tri = gmap[tri_g]
    if np.any(tri < 0):
        raise MeshError("gmsh triangles reference unknown nodes")
    return coords[new_k].copy(), tri


@dataclass
class Stitch:
    """Result of replacing a patch: the new mesh and the index maps."""

    mesh: Mesh
    kept_elements: np.ndarray   # old indices of the elements kept (new indices 0..len-1)
    patch_elements: np.ndarray  # old indices of the replaced elements
    n_new_elements: int         # new patch elements, indices len(kept)..end
    kept_nodes: np.ndarray      # old indices of the nodes kept (new indices 0..len-1)
    n_new_nodes: int            # new interior nodes, appended


def stitch(mesh: Mesh, mask: np.ndarray, new_nodes: np.ndarray, new_tri: np.ndarray) -> Stitch:
    """Replace the elements in ``mask`` by ``new_tri`` (indices as returned by
    :func:`mesh_patch`) and renumber nodes and elements."""
    n_old = mesh.n_nodes
    tri = mesh.triangles
    keep_el = np.flatnonzero(~mask)
    patch_el = np.flatnonzero(mask)
    used = np.zeros(n_old + len(new_nodes), bool)
    used[tri[keep_el].ravel()] = True
    used[new_tri.ravel()] = True
    used[mesh.boundary_edges.ravel()] = True
    kept_nodes = np.flatnonzero(used[:n_old])
    new_used = np.flatnonzero(used[n_old:])
    renum = np.full(n_old + len(new_nodes), -1, np.int64)
    renum[kept_nodes] = np.arange(len(kept_nodes))
    renum[n_old + new_used] = len(kept_nodes) + np.arange(len(new_used))
    tri_new = renum[new_tri]
    # CCW orientation
    allnodes = np.concatenate([mesh.nodes[kept_nodes], new_nodes[new_used]])
    a = signed_areas(allnodes, tri_new)
    flip = a < 0
    tri_new[flip] = tri_new[flip][:, [0, 2, 1]]
    triangles = np.concatenate([renum[tri[keep_el]], tri_new])
    be = renum[mesh.boundary_edges]
    if np.any(be < 0) or np.any(triangles < 0):
        raise MeshError("stitching lost a node")
    new_mesh = Mesh(allnodes, triangles, be, mesh.boundary_tags.copy(), mesh.tag_names)
    return Stitch(new_mesh, keep_el, patch_el, len(tri_new), kept_nodes, len(new_used))
