"""Element strain-rate invariants used by outputs and plots."""
import numpy as np


def invariants(eps: np.ndarray):
    """(divergence, maximum shear, total) [s-1] of (m, 3) strain rates
    (ε̇xx, ε̇yy, ε̇xy): ε̇I = ε̇xx + ε̇yy, ε̇II = sqrt((ε̇xx − ε̇yy)² + 4 ε̇xy²),
    ε̇tot = sqrt(ε̇I² + ε̇II²)."""
    div = eps[:, 0] + eps[:, 1]
    shear = np.sqrt((eps[:, 0] - eps[:, 1]) ** 2 + 4.0 * eps[:, 2] ** 2)
    return div, shear, np.hypot(div, shear)
