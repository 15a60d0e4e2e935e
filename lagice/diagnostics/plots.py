"""PNG figures of the diagnostics (matplotlib, Agg canvas; no global backend change).

Figures follow Girard et al. 2011: scaling (Fig. 5), PDFs with tail fits (Fig. 4), and
maps of the deformation rate on the triangles (Fig. 3).
"""

from pathlib import Path

import numpy as np

from lagice.io.cf import save_figure_atomic


def _figure(width_in=6.0, height_in=4.5, ncols=1):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width_in * ncols, height_in))
    FigureCanvasAgg(fig)
    return fig


def plot_scaling(x, mean, fit, path, xlabel, title):
    """Log–log plot of ⟨ε̇tot⟩ (s-1) against scale x with the fitted power law.

    Parameters
    ----------
    x, mean : array_like
        Scale (m or s) and mean total deformation rate (s-1).
    fit : lagice.diagnostics.PowerLawFit
    path : str or Path
        PNG file written.
    xlabel, title : str
    """
    fig = _figure()
    ax = fig.add_subplot(111)
    x = np.asarray(x, float)
    mean = np.asarray(mean, float)
    ok = np.isfinite(mean) & (mean > 0) & (x > 0)
    ax.loglog(x[ok], mean[ok], "o", label="⟨ε̇tot⟩")
    if np.isfinite(fit.exponent):
        xs = np.geomspace(fit.fit_range[0], fit.fit_range[1], 50)
        err = f" ± {fit.exponent_stderr:.2f}" if np.isfinite(fit.exponent_stderr) else ""
        ax.loglog(xs, fit.prefactor * xs ** (-fit.exponent), "k--",
                  label=f"fit: exponent {fit.exponent:.3f}{err}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("mean total deformation rate (s$^{-1}$)")
    ax.set_title(title)
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save_figure_atomic(fig, path, dpi=120)
    return Path(path)


def plot_pdfs(pdfs, tails, path):
    """Log-binned PDFs of shear and |divergence| (s-1) with their ML tail fits.

    Parameters
    ----------
    pdfs : dict name -> LogBinnedPdf
    tails : dict name -> PowerLawTail
    path : str or Path
        PNG file written.
    """
    fig = _figure(ncols=len(pdfs))
    for k, (name, pdf) in enumerate(pdfs.items()):
        ax = fig.add_subplot(1, len(pdfs), k + 1)
        ok = pdf.density > 0
        ax.loglog(pdf.bin_centres[ok], pdf.density[ok], "o", ms=4, label="PDF")
        tail = tails.get(name)
        if tail is not None and np.isfinite(tail.exponent):
            # p(x) = (n_tail / n_total) (γ−1)/x_min (x/x_min)^−γ on x ≥ x_min
            xs = np.geomspace(tail.x_min, tail.x_max, 50)
            amp = tail.n_tail / max(pdf.n_total, 1) * (tail.exponent - 1) / tail.x_min
            ax.loglog(xs, amp * (xs / tail.x_min) ** (-tail.exponent), "k--",
                      label=f"tail γ = {tail.exponent:.2f} ± {tail.exponent_stderr:.2f}")
        ax.set_xlabel(f"{name} rate (s$^{{-1}}$)")
        ax.set_ylabel("probability density (s)")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save_figure_atomic(fig, path, dpi=120)
    return Path(path)


def plot_map(nodes_xy, triangles, values_s, path, title="log10 total deformation rate (s-1)", decades=4.0):
    """Map of log10 of an element field (s-1) on the triangles (Girard et al. 2011 Fig. 3).

    The colour range spans ``decades`` decades below the 99.5th percentile of
    the positive values; smaller values (zeros and round-off of Lagrangian
    differences included) are drawn with the lowest colour.
    """
    fig = _figure(6.0, 5.5)
    ax = fig.add_subplot(111)
    v = np.asarray(values_s, float)
    pos = v[v > 0]
    vmax = float(np.percentile(np.log10(pos), 99.5)) if pos.size else 0.0
    vmin = vmax - float(decades)
    logv = np.log10(np.maximum(v, 10.0**vmin))
    xy = np.asarray(nodes_xy, float) / 1e3
    tpc = ax.tripcolor(xy[:, 0], xy[:, 1], np.asarray(triangles), facecolors=logv, cmap="viridis",
                       vmin=vmin, vmax=vmax)
    fig.colorbar(tpc, ax=ax, label="log10 rate (s$^{-1}$)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (km)")
    ax.set_ylabel("y (km)")
    ax.set_title(title)
    fig.tight_layout()
    save_figure_atomic(fig, path, dpi=120)
    return Path(path)
