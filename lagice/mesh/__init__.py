"""Triangular meshes: generation (gmsh), topology, quality, I/O (meshio)."""
from .core import COAST, OPEN, Mesh, boundary_edges_of, node_element_adjacency, signed_areas
from .generate import generate_mesh, gmsh_session, rectangle_domain, validate_polygon
from .io import read_mesh, write_mesh
from .quality import angles_deg, edge_lengths, quality_report, size_line, size_report
from .transform import morton_order, renumber_for_locality, rotate_mesh

__all__ = [
    "COAST", "OPEN", "Mesh", "boundary_edges_of", "node_element_adjacency", "signed_areas",
    "generate_mesh", "gmsh_session", "rectangle_domain", "validate_polygon", "read_mesh",
    "write_mesh", "angles_deg", "edge_lengths", "quality_report", "size_report", "size_line", "morton_order",
    "renumber_for_locality", "rotate_mesh",
]
