"""Pictures of tablets with matplotlib (PNG): shaded faces, one colour per patch, patch boundaries."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from tabletcad.io.atomic import atomic_path
from tabletcad.tablet import Tablet

__all__ = ["plot_tablet", "tablet_figure", "tablet_png"]


def _quads(Y: np.ndarray) -> np.ndarray:
    """Quadrilaterals (k, 4, 3) of a grid of points (ns, nt, 3)."""
    return np.stack([Y[:-1, :-1], Y[1:, :-1], Y[1:, 1:], Y[:-1, 1:]], axis=-2).reshape(-1, 4, 3)


def tablet_figure(
    tablet: Tablet,
    *,
    nu: int = 33,
    nv: int = 97,
    title: str | None = None,
    elev: float = 24.0,
    azim: float = -60.0,
) -> Path:
    """Render the tablet's faces (Lambert-shaded, one colour per patch, cut faces grey)
    with the patch boundary curves in black, to a PNG.

    All faces go into one polygon collection so that matplotlib sorts them by
    depth together (separate surfaces are drawn in artist order and hide each
    other wrongly).
    """
    from matplotlib import colormaps
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = Figure(figsize=(6.4, 5.6))
    FigureCanvasAgg(fig)  # no global backend: the figure owns its Agg canvas
    ax = fig.add_subplot(111, projection="3d")
    colours = colormaps["tab10"]
    el, az = np.radians(elev), np.radians(azim)
    view = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    light = view + np.array([0.3, -0.2, 0.6])
    light /= np.linalg.norm(light)
    polys, cols, edges, allpts = [], [], [], []
    for face in tablet.faces():
        s = np.linspace(face.s_range[0], face.s_range[1], nu)
        t = np.linspace(face.t_range[0], face.t_range[1], nv)
        Y = face.evaluate_grid(tablet, s, t)
        q = _quads(Y)
        n = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1])
        n /= np.maximum(np.linalg.norm(n, axis=-1), 1e-300)[:, None]
        lam = np.abs(n @ light)  # two-sided Lambert
        base = np.array(colours(face.patch % 10)[:3]) if face.kind == "w" else np.array([0.72, 0.72, 0.72])
        c = np.clip(base[None, :] * (0.35 + 0.75 * lam[:, None]), 0.0, 1.0)
        polys.append(q)
        cols.append(c)
        if face.kind == "w":
            edges.extend([Y[0], Y[-1]])
        allpts.append(Y.reshape(-1, 3))
    coll = Poly3DCollection(np.concatenate(polys), facecolors=np.concatenate(cols), linewidths=0.0, antialiased=False)
    ax.add_collection3d(coll)
    for e in edges:
        ax.plot(e[:, 0], e[:, 1], e[:, 2], color="k", linewidth=0.6)
    pts = np.vstack(allpts)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    c = (lo + hi) / 2
    r = float(np.max(hi - lo)) / 2 or 1.0
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.view_init(elev=elev, azim=azim)
    ax.set_title(title or f"{tablet.name} ({tablet.family}, {len(tablet.patches)} patches)")
    return fig


def tablet_png(tablet: Tablet, *, dpi: int = 130, **kw) -> bytes:
    """The picture of :func:`tablet_figure` as PNG bytes (for notebooks' ``_repr_png_``)."""
    buf = io.BytesIO()
    tablet_figure(tablet, **kw).savefig(buf, dpi=dpi, format="png", bbox_inches="tight")
    return buf.getvalue()


def plot_tablet(tablet: Tablet, path: str | Path, *, dpi: int = 130, **kw) -> Path:
    """Write the picture of :func:`tablet_figure` to ``path`` (PNG, written atomically)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tablet_figure(tablet, **kw).savefig(tmp, dpi=dpi, format="png", bbox_inches="tight")
    return path
