"""Pictures of tablets with matplotlib (PNG), drawn to scale.

:func:`tablet_figure` puts three panels side by side, all with equal axes in
mm: a shaded 3-D view (one colour per patch, a low light that brings out the
cups), the true side profile (the silhouette seen along ``y``, filled) and the
plan (top faces hill-shaded), dimensioned with the diameter or length ×
width, the band, the overall thickness and the cup depth.
:func:`tablets_figure` draws several tablets' profiles and plans at one scale.

No global matplotlib backend is set: every figure is a
:class:`matplotlib.figure.Figure` with its own Agg canvas.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from tabletcad.io.atomic import atomic_path
from tabletcad.geometry.tablet import Tablet

__all__ = ["plot_tablet", "plot_tablets", "tablet_figure", "tablets_figure", "tablet_png", "side_profile",
           "TabletOutline"]

_LIGHT = np.array([-0.75, 0.45, 0.50]) / np.linalg.norm([-0.75, 0.45, 0.50])  # low, from the upper left


def _quads(Y: np.ndarray) -> np.ndarray:
    """Quadrilaterals (k, 4, 3) of a grid of points (ns, nt, 3)."""
    return np.stack([Y[:-1, :-1], Y[1:, :-1], Y[1:, 1:], Y[:-1, 1:]], axis=-2).reshape(-1, 4, 3)


def _face_grids(tablet: Tablet, nu: int, nv: int) -> list[tuple[object, np.ndarray]]:
    out = []
    for face in tablet.faces():
        s = np.linspace(face.s_range[0], face.s_range[1], nu)
        t = np.linspace(face.t_range[0], face.t_range[1], nv)
        out.append((face, face.evaluate_grid(tablet, s, t)))
    return out


@dataclass(frozen=True)
class TabletOutline:
    """Side profile and plan outline of a tablet (mm).

    ``x``: bin centres along x; ``z_low``/``z_high``: the silhouette seen along y
    (lowest and highest surface point over each x bin); ``plan``: closed outline
    (k, 2) seen from above; ``band``, ``thickness``, ``cup_depth`` (top face), ``length``,
    ``width``: the main dimensions.
    """

    x: np.ndarray
    z_low: np.ndarray
    z_high: np.ndarray
    plan: np.ndarray
    band: float
    thickness: float
    cup_depth: float
    length: float
    width: float
    round: bool


def side_profile(tablet: Tablet, n: int = 121, *, nu: int = 65, nv: int = 257,
                 grids: list | None = None) -> TabletOutline:
    """The side profile (silhouette along y), the plan outline and the main dimensions (mm).

    The band is the nominal's ``band_z`` when the family has one, else the silhouette's
    height at the rim; the cup depth is the top's height above the band's top.  Length, width
    and thickness are an industry family's exact nominal dimensions (its surface is certified
    within 1 µm of them), else the surface's polished extremes (:meth:`Tablet.bounds`).
    """
    grids = grids if grids is not None else _face_grids(tablet, nu, nv)
    P = np.vstack([Y.reshape(-1, 3) for _, Y in grids])
    lo, hi = P.min(axis=0), P.max(axis=0)
    edges = np.linspace(lo[0], hi[0], n + 1)
    k = np.clip(np.searchsorted(edges, P[:, 0], side="right") - 1, 0, n - 1)
    zl = np.full(n, np.inf)
    zh = np.full(n, -np.inf)
    np.minimum.at(zl, k, P[:, 2])
    np.maximum.at(zh, k, P[:, 2])
    x = 0.5 * (edges[:-1] + edges[1:])
    ok = np.isfinite(zl)
    x, zl, zh = x[ok], zl[ok], zh[ok]
    c = 0.5 * (lo[:2] + hi[:2])
    ang = np.arctan2(P[:, 1] - c[1], P[:, 0] - c[0])
    rad = np.hypot(P[:, 0] - c[0], P[:, 1] - c[1])
    m = 180  # outline: farthest point from the centre per 2 degrees (nv = 257 puts samples in each)
    ka = np.clip(((ang + np.pi) / (2 * np.pi) * m).astype(int), 0, m - 1)
    rmax = np.zeros(m)
    np.maximum.at(rmax, ka, rad)
    amid = np.linspace(-np.pi, np.pi, m, endpoint=False) + np.pi / m
    keep = rmax > 0
    plan = c + rmax[keep, None] * np.c_[np.cos(amid[keep]), np.sin(amid[keep])]
    plan = np.vstack([plan, plan[:1]])
    band_z = getattr(tablet.nominal, "band_z", None)
    if band_z is None:
        rim = slice(0, max(1, len(x) // 50))
        band_z = (float(np.max(zl[rim])), float(np.min(zh[rim])))
    band = float(band_z[1] - band_z[0])
    info = getattr(tablet.nominal, "info", None) or {}
    T = getattr(tablet.nominal, "thickness", None)
    if "length_mm" in info and "width_mm" in info and T is not None:
        # an industry family: its exact nominal dimensions (the surface is certified within 1 µm of
        # them), which a dimensioned drawing shows; standing on z = 0
        ext = np.array([info["length_mm"], info["width_mm"], T], dtype=float)
        top = float(T)
    else:
        blo, bhi = tablet.bounds()  # extremes polished on the surface, not just sampled
        ext = np.asarray(bhi) - np.asarray(blo)
        top = float(bhi[2])
    return TabletOutline(x=x, z_low=zl, z_high=zh, plan=plan, band=band, thickness=float(ext[2]),
                         cup_depth=max(0.0, top - float(band_z[1])), length=float(ext[0]), width=float(ext[1]),
                         round=abs(ext[0] - ext[1]) <= 1e-3 * max(ext[0], ext[1]))


def _dim(ax, p0, p1, text: str, *, offset=(0.0, 0.0), rotation: float = 0.0, fontsize: float = 7.0) -> None:
    """A dimension line with arrows between ``p0`` and ``p1`` (mm) and its label."""
    p0, p1, off = np.asarray(p0, float), np.asarray(p1, float), np.asarray(offset, float)
    ax.annotate("", xy=p1 + off, xytext=p0 + off,
                arrowprops=dict(arrowstyle="<|-|>", color="0.15", lw=0.6, shrinkA=0, shrinkB=0, mutation_scale=6))
    for p in (p0, p1):
        if np.any(off):
            ax.plot([p[0], p[0] + off[0]], [p[1], p[1] + off[1]], color="0.5", lw=0.4)
    mid = 0.5 * (p0 + p1) + off
    ax.text(mid[0], mid[1], text, fontsize=fontsize, rotation=rotation, ha="center", va="center",
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.9))


def _draw_profile(ax, o: TabletOutline, colour="#4e79a7", dims: bool = True) -> None:
    xs = np.r_[o.x, o.x[::-1]]
    zs = np.r_[o.z_high, o.z_low[::-1]]
    ax.fill(xs, zs, color=colour, alpha=0.35, lw=0)
    ax.plot(xs, zs, color="k", lw=0.8)
    ax.set_aspect("equal")
    if not dims:
        return
    x0, x1 = float(o.x[0]), float(o.x[-1])
    ztop, zbot = float(o.z_high.max()), float(o.z_low.min())
    rim_top = ztop - o.cup_depth
    pad = 0.06 * max(o.length, o.thickness)
    _dim(ax, (x0, ztop), (x0, zbot), f"{o.thickness:.3g}", offset=(-pad, 0), rotation=90)
    _dim(ax, (x1, rim_top), (x1, rim_top - o.band), f"band {o.band:.3g}", offset=(pad, 0), rotation=90)
    if o.cup_depth > 1e-6:
        xc = float(o.x[np.argmax(o.z_high)])
        ax.plot([x0, x1], [rim_top, rim_top], color="0.5", lw=0.4, ls=":")
        _dim(ax, (xc, rim_top), (xc, ztop), f"cup {o.cup_depth:.3g}", offset=(0, 0))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_title("side profile", fontsize=9)
    ax.margins(0.2)


def _draw_plan(ax, tablet: Tablet, o: TabletOutline, grids, colour="#4e79a7", dims: bool = True) -> None:
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgb

    base = np.array(to_rgb(colour))
    polys, cols, depth = [], [], []
    for face, Y in grids:
        q = _quads(Y)
        n = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1])
        n /= np.maximum(np.linalg.norm(n, axis=-1), 1e-300)[:, None]
        seen = np.abs(n[:, 2]) > 1e-3  # walls are edge-on from above
        n = n[seen] * np.sign(n[seen, 2])[:, None]  # the normal facing the viewer
        lam = np.clip(n @ _LIGHT, 0.0, 1.0)
        polys.append(q[seen][:, :, :2])
        cols.append(np.clip(base[None, :] * (0.2 + 1.0 * lam[:, None] ** 2) + 0.05, 0, 1))
        depth.append(q[seen][:, :, 2].mean(axis=1))
    if polys:
        order = np.argsort(np.concatenate(depth), kind="stable")  # painter: the top face drawn last
        ax.add_collection(PolyCollection(np.concatenate(polys)[order], facecolors=np.concatenate(cols)[order],
                                         linewidths=0, antialiased=False))
    ax.plot(o.plan[:, 0], o.plan[:, 1], color="k", lw=0.8)
    ax.set_aspect("equal")
    ax.autoscale_view()
    if not dims:
        return
    lo, hi = o.plan.min(axis=0), o.plan.max(axis=0)
    pad = 0.08 * max(o.length, o.width)
    if o.round:
        _dim(ax, (lo[0], 0.5 * (lo[1] + hi[1])), (hi[0], 0.5 * (lo[1] + hi[1])), f"⌀ {o.length:.3g}",
             offset=(0, -0.5 * o.width - pad))
    else:
        _dim(ax, (lo[0], lo[1]), (hi[0], lo[1]), f"{o.length:.3g}", offset=(0, -pad))
        _dim(ax, (hi[0], lo[1]), (hi[0], hi[1]), f"{o.width:.3g}", offset=(pad, 0), rotation=90)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title("plan", fontsize=9)
    ax.margins(0.2)


def tablet_figure(
    tablet: Tablet,
    *,
    nu: int = 25,
    nv: int = 73,
    title: str | None = None,
    elev: float = 18.0,
    azim: float = -60.0,
):
    """A :class:`matplotlib.figure.Figure`: shaded 3-D view, dimensioned side profile and plan, to scale.

    All faces of the 3-D view go into one polygon collection so that matplotlib sorts
    them by depth together (separate surfaces hide each other wrongly).
    """
    from matplotlib import colormaps
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = Figure(figsize=(11.0, 4.0))
    FigureCanvasAgg(fig)  # no global backend: the figure owns its Agg canvas
    ax = fig.add_subplot(131, projection="3d")
    colours = colormaps["tab10"]
    grids = _face_grids(tablet, nu, nv)
    polys, cols, edges = [], [], []
    for face, Y in grids:
        q = _quads(Y)
        n = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1])
        n /= np.maximum(np.linalg.norm(n, axis=-1), 1e-300)[:, None]
        lam = np.abs(n @ _LIGHT)  # two-sided Lambert, light low from the upper left
        base = np.array(colours(face.patch % 10)[:3]) if face.kind == "w" else np.array([0.72, 0.72, 0.72])
        polys.append(q)
        # squared Lambert: the few degrees a cup tilts its faces show as a clear gradient
        cols.append(np.clip(base[None, :] * (0.2 + 1.0 * lam[:, None] ** 2), 0.0, 1.0))
        if face.kind == "w":
            edges.extend([Y[0], Y[-1]])
    ax.add_collection3d(Poly3DCollection(np.concatenate(polys), facecolors=np.concatenate(cols), linewidths=0.0,
                                         antialiased=False))
    for e in edges:
        ax.plot(e[:, 0], e[:, 1], e[:, 2], color="k", linewidth=0.5)
    pts = np.vstack([Y.reshape(-1, 3) for _, Y in grids])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-9)))  # equal scale on all three axes
    # a picture, not a chart: the profile and plan beside it carry the axes and the dimensions
    # (and the 3-D axes' panes, grids and ticks were half the drawing time)
    ax.set_axis_off()
    ax.view_init(elev=elev, azim=azim)
    o = side_profile(tablet)
    _draw_profile(fig.add_subplot(132), o)
    _draw_plan(fig.add_subplot(133), tablet, o, grids)
    fig.suptitle(title or f"{tablet.name} ({tablet.family}, {len(tablet.patches)} patches), mm", fontsize=10)
    fig.subplots_adjust(left=0.02, right=0.98, wspace=0.3)
    return fig


def tablets_figure(tablets: Sequence[Tablet], *, labels: Sequence[str] | None = None, nu: int = 25, nv: int = 73):
    """Side profiles (top row) and plans (bottom row) of several tablets at one scale (mm)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    k = len(tablets)
    if k == 0:
        raise ValueError("tablets_figure needs at least one tablet")
    labels = list(labels) if labels is not None else [t.name for t in tablets]
    fig = Figure(figsize=(2.6 * k + 0.6, 5.0))
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, k, squeeze=False, sharex="row", sharey="row")
    outlines = []
    for i, t in enumerate(tablets):
        grids = _face_grids(t, nu, nv)
        o = side_profile(t)
        outlines.append(o)
        colour = f"C{i % 10}"
        _draw_profile(axes[0, i], o, colour, dims=False)
        _draw_plan(axes[1, i], t, o, grids, colour, dims=False)
        axes[0, i].set_title(f"{labels[i]}\n{o.length:.3g}×{o.width:.3g}×{o.thickness:.3g}", fontsize=8)
    half = 0.55 * max(max(o.length, o.width) for o in outlines)
    zs = [z for o in outlines for z in (o.z_low.min(), o.z_high.max())]
    zc = 0.5 * (min(zs) + max(zs))
    hz = 0.6 * (max(zs) - min(zs))
    for o, a0, a1 in zip(outlines, axes[0], axes[1]):
        cx = 0.5 * (o.x[0] + o.x[-1])
        a0.set_xlim(cx - half, cx + half)
        a0.set_ylim(zc - hz, zc + hz)
        a1.set_ylim(-half, half)
    axes[0, 0].set_ylabel("z (mm)")
    axes[1, 0].set_ylabel("y (mm)")
    for a in axes[1]:
        a.set_xlabel("x (mm)")
    return fig


def tablet_png(tablet: Tablet, *, dpi: int = 110, **kw) -> bytes:
    """The picture of :func:`tablet_figure` as PNG bytes (for notebooks' ``_repr_png_``)."""
    buf = io.BytesIO()
    tablet_figure(tablet, **kw).savefig(buf, dpi=dpi, format="png", pil_kwargs=_PNG)
    return buf.getvalue()


#: zlib level 1: the same pixels (PNG is lossless) in a file ~20 % larger, encoded in a tenth of
#: the time of the default level (benchmarks/bench_plot.py)
_PNG = {"compress_level": 1}


def _save(fig, path: str | Path, dpi: int) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png", pil_kwargs=_PNG)
    return path


def plot_tablet(tablet: Tablet, path: str | Path, *, dpi: int = 110, **kw) -> Path:
    """Write the picture of :func:`tablet_figure` to ``path`` (PNG, written atomically)."""
    return _save(tablet_figure(tablet, **kw), path, dpi)


def plot_tablets(tablets: Sequence[Tablet], path: str | Path, *, dpi: int = 110, **kw) -> Path:
    """Write :func:`tablets_figure` (several tablets at one scale) to ``path`` (PNG)."""
    return _save(tablets_figure(tablets, **kw), path, dpi)
