"""Pictures of tablets with matplotlib (PNG), patch by patch with their boundaries."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tabletcad.io.atomic import atomic_path
from tabletcad.tablet import Tablet

__all__ = ["plot_tablet"]


def plot_tablet(tablet: Tablet, path: str | Path, *, dpi: int = 130, nu: int = 41, nv: int = 97, title: str | None = None) -> Path:
    """Render the tablet's patches (shaded, one colour each, boundary curves in black) to a PNG.

    Trimmed tablets show their cut faces' outlines; ``w < 1`` inner walls are drawn too.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.colors import LightSource

    fig = plt.figure(figsize=(6.4, 5.6))
    ax = fig.add_subplot(111, projection="3d")
    colours = plt.get_cmap("tab10")
    ls = LightSource(azdeg=315, altdeg=35)
    allpts = []
    for face in tablet.faces():
        s = np.linspace(face.s_range[0], face.s_range[1], nu)
        tt = np.linspace(face.t_range[0], face.t_range[1], nv)
        Y = face.evaluate_grid(tablet, s, tt)
        rgb = np.array(colours(face.patch % 10)[:3]) if face.kind == "w" else np.array([0.75, 0.75, 0.75])
        shade = ls.shade_rgb(np.broadcast_to(rgb, Y.shape[:2] + (3,)), Y[..., 2])
        ax.plot_surface(Y[..., 0], Y[..., 1], Y[..., 2], facecolors=shade, rstride=1, cstride=1,
                        linewidth=0, antialiased=True, shade=False)
        for edge in (Y[0], Y[-1]):
            ax.plot(edge[:, 0], edge[:, 1], edge[:, 2], color="k", linewidth=0.7)
        allpts.append(Y.reshape(-1, 3))
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
    ax.view_init(elev=22, azim=-60)
    ax.set_title(title or f"{tablet.name} ({tablet.family}, {len(tablet.patches)} patches)")
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png", bbox_inches="tight")
    plt.close(fig)
    return path
