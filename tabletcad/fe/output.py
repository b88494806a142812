"""Files of an FE result: ``stress.vtu`` (meshio) and a picture of a stress on a plane section.

Both are written atomically (:mod:`tabletcad.io.atomic`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tabletcad.fe.elasticity import ElasticSolution, principal_stresses, von_mises
from tabletcad.io.atomic import atomic_path
from tabletcad.io.figures import save_figure

__all__ = ["write_vtu", "section", "plot_section"]


def write_vtu(sol: ElasticSolution, path: str | Path) -> Path:
    """Write the mesh, displacement (mm, point data) and element-mean stresses (MPa, cell data)."""
    import meshio

    s = sol.vertex_stress.mean(axis=1)  # (m, 3, 3)
    cell = {
        "stress_MPa": [s.reshape(-1, 9)],
        "max_principal_stress_MPa": [principal_stresses(s)[:, -1]],
        "von_mises_MPa": [von_mises(s)],
    }
    for i, a in enumerate("xyz"):
        cell[f"sigma_{a}{a}_MPa"] = [s[:, i, i]]
    mesh = meshio.Mesh(sol.mesh.p.T, [("tetra", sol.mesh.t.T)],
                       point_data={"displacement_mm": sol.displacement}, cell_data=cell)
    with atomic_path(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
    return Path(path)


def section(sol: ElasticSolution, axis: int, level: float,
            component: tuple[int, int] | str) -> tuple[np.ndarray, np.ndarray]:
    """Exact cut of the mesh by the plane ``x[axis] = level``.

    Returns triangles ``(k, 3, 3)`` (mm) and the stress component at their
    corners ``(k, 3)`` (MPa; ``component`` is a tensor index pair or ``"von_mises"``), interpolated linearly along the cut edges from the
    vertex-averaged stress field (:meth:`ElasticSolution.nodal_stress`).
    """
    m = sol.mesh
    X = m.p[:, m.t].transpose(2, 1, 0)  # (m, 4, 3)
    nodal = sol.nodal_stress()
    field = von_mises(nodal) if component == "von_mises" else nodal[:, component[0], component[1]]
    S = field[m.t.T]  # (m, 4), vertex-averaged field
    d = X[..., axis] - level
    tris, vals = [], []
    cross = (d.min(axis=1) < 0) & (d.max(axis=1) > 0)
    edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    for e in np.flatnonzero(cross):
        pts, sv = [], []
        for i, j in edges:
            if (d[e, i] < 0) != (d[e, j] < 0):
                w = d[e, i] / (d[e, i] - d[e, j])
                pts.append(X[e, i] + w * (X[e, j] - X[e, i]))
                sv.append(S[e, i] + w * (S[e, j] - S[e, i]))
        pts, sv = np.array(pts), np.array(sv)
        if len(pts) == 4:  # quadrilateral: order around its centroid, split in two
            other = [k for k in range(3) if k != axis]
            q = pts[:, other] - pts[:, other].mean(axis=0)
            o = np.argsort(np.arctan2(q[:, 1], q[:, 0]))
            pts, sv = pts[o], sv[o]
            tris += [pts[[0, 1, 2]], pts[[0, 2, 3]]]
            vals += [sv[[0, 1, 2]], sv[[0, 2, 3]]]
        elif len(pts) == 3:
            tris.append(pts)
            vals.append(sv)
    return np.array(tris).reshape(-1, 3, 3), np.array(vals).reshape(-1, 3)


def plot_section(sol: ElasticSolution, path: str | Path, *, axis: int, level: float,
                 component: tuple[int, int] | str, title: str, label: str,
                 limits: tuple[float, float] | None = None) -> Path:
    """Picture (PNG/SVG/PDF by suffix) of a stress component on the section ``x[axis] = level``.

    ``limits`` (MPa) clip the colour scale (default: ±the 99th percentile of |value|).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.tri import Triangulation

    tris, vals = section(sol, axis, level, component)
    other = [k for k in range(3) if k != axis]
    xy = tris[..., other].reshape(-1, 2)
    tri = Triangulation(xy[:, 0], xy[:, 1], np.arange(len(xy)).reshape(-1, 3))
    fig = Figure(figsize=(6.4, 5.2))
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
    ax = fig.subplots()
    lim = float(np.percentile(np.abs(vals), 99)) or 1.0
    if limits is None:
        limits = (0.0, lim) if component == "von_mises" else (-lim, lim)
    cmap = "viridis" if component == "von_mises" else "coolwarm"
    tpc = ax.tripcolor(tri, vals.ravel(), shading="gouraud", cmap=cmap, vmin=limits[0], vmax=limits[1])
    fig.colorbar(tpc, ax=ax, label=label)
    names = "xyz"
    ax.set_xlabel(f"{names[other[0]]} (mm)")
    ax.set_ylabel(f"{names[other[1]]} (mm)")
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    return save_figure(fig, Path(path), dpi=120)
