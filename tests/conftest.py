import numpy as np
import pytest

from lagice.mesh import generate_mesh, rectangle_domain


@pytest.fixture(scope="session")
def plate_mesh():
    """An irregular gmsh mesh of a 100 km x 200 km plate, tagged sides."""
    poly, segs = rectangle_domain(100e3, 200e3)
    return generate_mesh(poly, 12e3, segments=segs)


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
