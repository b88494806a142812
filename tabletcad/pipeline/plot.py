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
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.io.figures import save_figure
from tabletcad.geometry.tablet import Tablet
from tabletcad.geometry.vectors import cross

__all__ = ["plot_tablet", "plot_tablets", "tablet_figure", "tablets_figure", "tablet_png", "side_profile",
           "TabletOutline", "view_axes"]

_LIGHT = np.array([-0.75, 0.45, 0.50]) / np.linalg.norm([-0.75, 0.45, 0.50])  # low, from the upper left


def _quads(Y: np.ndarray) -> np.ndarray:
    """Quadrilaterals (k, 4, 3) of a grid of points (ns, nt, 3)."""
    return np.stack([Y[:-1, :-1], Y[1:, :-1], Y[1:, 1:], Y[:-1, 1:]], axis=-2).reshape(-1, 4, 3)


def _face_grids(tablet: Tablet, nu: int, nv: int, faces: list | None = None) -> list[tuple[object, np.ndarray]]:
    out = []
    for face in tablet.faces() if faces is None else faces:
        s = np.linspace(face.s_range[0], face.s_range[1], nu)
        t = np.linspace(face.t_range[0], face.t_range[1], nv)
        out.append((face, face.evaluate_grid(tablet, s, t)))
    return out


def _as_tablet(obj) -> Tablet:
    """``obj`` itself when it is a :class:`Tablet`, else its ``.tablet`` (a :class:`TabletModel`...)."""
    t = obj if isinstance(obj, Tablet) else getattr(obj, "tablet", None)
    if not isinstance(t, Tablet):
        raise TypeError(f"expected a Tablet or an object with a .tablet (a TabletModel), got {type(obj).__name__}")
    return t


@dataclass(frozen=True)
class TabletOutline:
    """Side profile and plan outline of a tablet (mm).

    ``x``: abscissae along x (from the least to the greatest x of the tablet, denser towards
    both ends); ``z_low``/``z_high``: the silhouette seen along y (lowest and highest point of
    the tablet over each x); ``plan``: closed outline (k, 2) seen from above, ``plan_holes``
    the closed outlines of see-through holes (a ring); ``band``, ``thickness``, ``cup_depth``
    (top face), ``cup_depth_bottom``, ``length``, ``width``: the main dimensions;
    ``has_band``: False for a tablet without a band (a sphere: ``band`` and the cup depths are
    then only the silhouette's height at its ends and the heights beyond it, and are not drawn).
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
    cup_depth_bottom: float = 0.0
    plan_holes: tuple = ()
    has_band: bool = True


def _revolution_axis(tablet: Tablet) -> np.ndarray | None:
    """The plan point ``(x, y)`` of the vertical axis the (untrimmed in u and v) tablet is a
    surface of revolution about, or None: every ``u`` ring of every patch is a horizontal circle
    about one axis (within 1e-9 of the size)."""
    t = tablet.trim
    if t.u != (0.0, 1.0) or not t.full_v:
        return None
    segs = getattr(getattr(tablet.nominal, "outline", None), "segs", None)
    if segs is not None and not (len(segs) == 1 and segs[0].kind == "arc"):
        return None  # an industry family's outline that is not a circle
    u = np.linspace(0.0, 1.0, 9)
    v = np.linspace(0.0, math.tau, 24, endpoint=False)
    c = None
    for p in tablet.patches:  # patch by patch: a shaped tablet fails at its first patch
        X = p.evaluate_grid(u, v)  # (9, 24, 3)
        if c is None:
            c = 0.5 * (X[..., :2].min(axis=(0, 1)) + X[..., :2].max(axis=(0, 1)))
        r = np.hypot(X[..., 0] - c[0], X[..., 1] - c[1])
        tol = 1e-9 * max(1.0, float(np.max(np.abs(X))))
        if float(np.max(np.ptp(r, axis=-1))) > tol or float(np.max(np.ptp(X[..., 2], axis=-1))) > tol:
            return None
    return c


def _abscissae(x0: float, x1: float, n: int) -> np.ndarray:
    """``n`` abscissae from ``x0`` to ``x1`` (both reached), Chebyshev-spaced: dense where a
    rounded end's silhouette turns vertical."""
    return x0 + (x1 - x0) * 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, n)))


def _crossings(lines: list[np.ndarray], xs: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest ``z`` where the polylines ``lines`` (arrays (..., m, 2) of (x, z)) cross
    each vertical ``x = xs[k]`` (``xs`` increasing; linear between points; a segment along the
    vertical gives both its ends); ``±inf`` where none does."""
    zl = np.full(xs.size, np.inf)
    zh = np.full(xs.size, -np.inf)
    for L in lines:
        xa, za = L[..., :-1, 0].ravel(), L[..., :-1, 1].ravel()
        xb, zb = L[..., 1:, 0].ravel(), L[..., 1:, 1].ravel()
        k0 = np.searchsorted(xs, np.minimum(xa, xb) - eps, side="left")
        cnt = np.searchsorted(xs, np.maximum(xa, xb) + eps, side="right") - k0
        sel = np.flatnonzero(cnt > 0)  # most short segments cross no vertical
        if sel.size == 0:
            continue
        cnt = cnt[sel]
        seg = np.repeat(sel, cnt)
        k = np.repeat(k0[sel] - (np.cumsum(cnt) - cnt), cnt) + np.arange(seg.size)
        xa, za, xb, zb = xa[seg], za[seg], xb[seg], zb[seg]
        dx = xb - xa
        along = np.abs(dx) <= 2.0 * eps
        t = np.clip((xs[k] - xa) / np.where(along, 1.0, dx), 0.0, 1.0)
        z = za + t * (zb - za)
        np.minimum.at(zl, k, np.where(along, np.minimum(za, zb), z))
        np.maximum.at(zh, k, np.where(along, np.maximum(za, zb), z))
    return zl, zh


def _seg_points(outline) -> np.ndarray:
    """Closed polyline (k, 2) of a chain of lines and arcs (``outline.segs``), arcs every ≤ 0.25°
    and at their points of greatest and least x and y (the outline's extents are exact)."""
    pts = []
    for s in outline.segs:
        if s.kind == "line":
            pts.append(np.asarray([s.p0], float))
            continue
        m = max(2, int(math.ceil(abs(s.sweep) / math.radians(0.25))))
        t = np.linspace(0.0, 1.0, m, endpoint=False)
        lo, hi = sorted((s.theta0, s.theta0 + s.sweep))
        quad = np.arange(math.ceil(lo / (0.5 * math.pi)), math.floor(hi / (0.5 * math.pi)) + 1) * (0.5 * math.pi)
        tq = (quad - s.theta0) / s.sweep
        t = np.unique(np.r_[t, tq[(tq > 0.0) & (tq < 1.0)]])
        pts.append(s.point(t))
    P = np.vstack(pts)
    return np.vstack([P, P[:1]])


def _plan(tablet: Tablet, band, axis: np.ndarray | None = None, radius: float = 0.0) -> tuple[np.ndarray, tuple]:
    """The plan outline (closed, (k, 2)) and the outlines of see-through holes.

    Exact where the tablet has one: an industry family's nominal outline (lines and arcs);
    else the band patch's edge curve (the band is the side wall the die forms: its edge is the
    outline, the PDE band bulging beyond it by at most :attr:`Band.bulge`); else, with no band,
    for a tablet of revolution about ``axis`` (a sphere, a spheroid) the circle of its greatest
    ``radius``, and for any other, per ``v`` the point of greatest plan radius over ``u`` and the
    patches on a dense grid (exact for coaxial patches star-shaped about the axis).  A tablet
    trimmed in ``v`` (a cut-away view) adds the cut faces, which run to the axis.
    """
    t = tablet.trim
    segs = getattr(getattr(tablet.nominal, "outline", None), "segs", None)
    if segs and t.u == (0.0, 1.0) and t.full_v and t.w[0] == 0.0:  # (an outline through points has no segs)
        return _seg_points(tablet.nominal.outline), ()
    nv = 1441
    v = np.linspace(t.v[0], t.v[1], nv)
    if band is not None and t.u == (0.0, 1.0):
        p = tablet.patches[band.patch]
        X = p.evaluate(0.0, v)[:, :2]
        axis = p.spine(np.array([0.5]))[0, :2]
    elif axis is not None:
        X = axis + radius * np.c_[np.cos(v), np.sin(v)]
    else:
        u = np.linspace(t.u[0], t.u[1], 257)
        G = np.stack([p.evaluate_grid(u, v)[..., :2] for p in tablet.patches])  # (patches, nu, nv, 2)
        axis = tablet.patches[0].spine(np.array([0.5]))[0, :2]
        c = 0.5 * (G.min(axis=(0, 1, 2)) + G.max(axis=(0, 1, 2))) if t.full_v else axis
        r = np.hypot(G[..., 0] - c[0], G[..., 1] - c[1]).reshape(-1, nv)
        X = G.reshape(-1, nv, 2)[np.argmax(r, axis=0), np.arange(nv)]
    if not t.full_v:
        X = np.vstack([axis, X, axis])
    holes = ()
    if t.w[0] > 0.0:  # a hollow solid (ring): the inner wall, nearest the axis over u and the patches
        u = np.linspace(t.u[0], t.u[1], 129)
        inner = []
        for p in tablet.patches:
            A = p.spine(u)[:, None, :2]
            inner.append(A + t.w[0] * (p.evaluate_grid(u, v)[..., :2] - A))
        inner = np.concatenate(inner)  # (patches·nu, nv, 2)
        r = np.hypot(inner[..., 0] - axis[0], inner[..., 1] - axis[1])
        holes = (inner[np.argmin(r, axis=0), np.arange(nv)],)
    return X, holes


def side_profile(tablet: Tablet, n: int = 121, *, nu: int = 65, nv: int = 257,
                 grids: list | None = None) -> TabletOutline:
    """The side profile (silhouette along y), the plan outline and the main dimensions (mm).

    ``tablet``: a :class:`Tablet` or anything with a ``.tablet``.  The silhouette is the tablet's
    true outline seen along y, from its least to its greatest x (``n`` abscissae, denser
    towards the ends): for a tablet of revolution, from its meridian (513 points a patch: at
    each ``x``, the highest and lowest meridian point at least ``|x|`` from the axis); else
    where the grid lines of a dense sample of its faces (``nu`` × ``nv`` each, or ``grids``)
    cross each vertical ``x = const`` (linear between grid points), its ends from the sample's
    extreme points.  The plan outline: see :func:`_plan`.  The band is the nominal's ``band_z``
    when the family has one, else the band patch's heights (:meth:`Tablet.band`), else (no band:
    a sphere) the silhouette's height at its ends; the cup depths are the top's height above the
    band and the band's height above the bottom.  Length, width and thickness are an industry
    family's exact nominal dimensions (its surface is certified within 1 µm of them), else the
    surface's polished extremes (:meth:`Tablet.bounds`), as the reports give them (also for a
    cut-away view of a family tablet: its own extents, not the whole tablet's).
    """
    return _side_profile(_as_tablet(tablet), n, nu, nv, grids, None)


def _round(tablet: Tablet, ext: np.ndarray, plan: np.ndarray) -> bool:
    """Whether the plan is dimensioned by a diameter: as long as wide and, for a cut-away, still
    spanning a diameter (a quarter of a round is as long as wide, no circle: it showed "⌀ 5" on a
    10 mm tablet; three quarters keep the diameter)."""
    if abs(ext[0] - ext[1]) > 1e-3 * max(ext[0], ext[1]):
        return False
    return tablet.trim.full_v or abs(ext[0] - 2.0 * float(np.max(np.hypot(plan[:, 0], plan[:, 1])))) <= 1e-3 * ext[0]


def _side_profile(tablet: Tablet, n: int, nu: int, nv: int, grids: list | None, faces: list | None) -> TabletOutline:
    nominal = tablet.nominal
    band_z = getattr(nominal, "band_z", None)
    exact_outline = getattr(getattr(nominal, "outline", None), "segs", None) is not None
    # an industry family has its band and outline exactly: no need to look for the band patch
    band = None if band_z is not None and exact_outline else tablet.band()
    info = getattr(nominal, "info", None) or {}
    T = getattr(nominal, "thickness", None)
    axis = _revolution_axis(tablet)
    M = None
    if axis is not None:  # the meridian (the surfaces w = 1 at v = 0)
        u = np.linspace(0.0, 1.0, 513)
        M = np.stack([p.evaluate(u, np.zeros_like(u)) for p in tablet.patches])  # (patches, 513, 3)
        rho = np.hypot(M[..., 0] - axis[0], M[..., 1] - axis[1])
    plan, holes = _plan(tablet, band, axis, float(rho.max()) if M is not None else 0.0)
    if tablet.trim.whole and "length_mm" in info and "width_mm" in info and T is not None:
        # an industry family: its exact nominal dimensions (the surface is certified within 1 µm of
        # them), which a dimensioned drawing shows; standing on z = 0
        ext = np.array([info["length_mm"], info["width_mm"], T], dtype=float)
        top, bottom = float(T), 0.0
        xr = (float(plan[:, 0].min()), float(plan[:, 0].max()))
    else:
        blo, bhi = tablet.bounds()  # extremes polished on the surface, not just sampled
        ext = np.asarray(bhi) - np.asarray(blo)
        top, bottom = float(bhi[2]), float(blo[2])
        xr = (float(blo[0]), float(bhi[0]))
    scale = max(1.0, float(np.max(np.abs(plan))), abs(top), abs(bottom))
    eps = 1e-9 * scale
    if M is not None:
        R = float(rho.max())
        x = _abscissae(axis[0] - R, axis[0] + R, n)
        lines = [np.stack([axis[0] + rho, M[..., 2]], -1), np.stack([axis[0] - rho, M[..., 2]], -1)]
        zl, zh = _crossings(lines, x, eps)
        # the section seen along y: z is covered at x where the meridian reaches |x| from the axis
        # at that height, so its extremes also come from meridian points beyond |x| (a flat top, a ring)
        order = np.argsort(-rho, axis=None)
        rs, zs = rho.reshape(-1)[order], M[..., 2].reshape(-1)[order]
        cnt = np.searchsorted(-rs, -(np.abs(x - axis[0]) - eps), side="right")
        hit = cnt > 0
        zl[hit] = np.minimum(zl[hit], np.minimum.accumulate(zs)[cnt[hit] - 1])
        zh[hit] = np.maximum(zh[hit], np.maximum.accumulate(zs)[cnt[hit] - 1])
    else:
        if grids is None:
            grids = _face_grids(tablet, nu, nv, faces)
        x = _abscissae(xr[0], xr[1], n)
        lines = []
        for _, Y in grids:
            xz = Y[..., [0, 2]]
            lines += [np.swapaxes(xz, 0, 1), xz]  # lines along s (one per t), along t (one per s)
        zl, zh = _crossings(lines, x, eps)
        # the ends: the sample's points at its least and greatest x (a band's wall)
        P = np.vstack([Y.reshape(-1, 3) for _, Y in grids])
        tol = (band.bulge if band is not None else 0.0) + 1e-6 * scale
        for k, sel in ((0, P[:, 0] <= P[:, 0].min() + tol), (-1, P[:, 0] >= P[:, 0].max() - tol)):
            zl[k] = min(zl[k], float(P[sel, 2].min()))
            zh[k] = max(zh[k], float(P[sel, 2].max()))
    ok = np.isfinite(zl) & np.isfinite(zh)
    x, zl, zh = x[ok], zl[ok], zh[ok]
    if band_z is None and band is not None:
        band_z = (band.z0, band.z1)
    has_band = band_z is not None
    if band_z is None:  # no band patch: the silhouette's height at its ends
        rim = slice(0, max(1, len(x) // 50))
        lo_, hi_ = float(np.max(zl[rim])), float(np.min(zh[rim]))
        band_z = (lo_, max(lo_, hi_))
    return TabletOutline(x=x, z_low=zl, z_high=zh, plan=plan, band=float(band_z[1] - band_z[0]),
                         thickness=float(ext[2]), cup_depth=max(0.0, top - float(band_z[1])), length=float(ext[0]),
                         width=float(ext[1]), round=_round(tablet, ext, plan),
                         cup_depth_bottom=max(0.0, float(band_z[0]) - bottom), plan_holes=holes, has_band=has_band)


def _scale_bar(ax, x0: float, y0: float, span: float) -> None:
    """A scale bar of a round length (1, 2 or 5 × 10^k mm, about a quarter of ``span``) from
    ``(x0, y0)`` (mm) to the right, labelled in mm.  The panels are dimensioned; the bar
    gives the scale in place of axis ticks (matplotlib's tick objects cost about half the
    picture's time, ``benchmarks/bench_plot.py``)."""
    target = 0.25 * span
    k = 10.0 ** math.floor(math.log10(target))
    bar = max(m * k for m in (1.0, 2.0, 5.0) if m * k <= target)
    ax.plot([x0, x0 + bar], [y0, y0], color="k", lw=1.6, solid_capstyle="butt")
    ax.annotate(f"{bar:g} mm", (x0 + 0.5 * bar, y0), xytext=(0.0, -2.0), textcoords="offset points",
                fontsize=7, ha="center", va="top")


def _panel_title(ax, text: str) -> None:
    """A panel's title as plain text above it (``Axes.set_title`` positions itself from the axis
    ticks, which the panels do not draw but matplotlib would build to ask)."""
    ax.text(0.5, 1.02, text, transform=ax.transAxes, fontsize=9, ha="center", va="bottom")


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
    from matplotlib.patches import Polygon

    xs = np.r_[o.x, o.x[::-1], o.x[:1]]  # closed: top left to right, bottom back, up the left band
    zs = np.r_[o.z_high, o.z_low[::-1], o.z_high[:1]]
    # the patch Axes.fill makes, added without its data limits (Axes.add_patch walks the path
    # segment by segment for them, 3 ms): the outline drawn next has the same points, and limits
    ax.add_artist(Polygon(np.column_stack([xs, zs]), closed=True, color=colour, alpha=0.35, lw=0))
    ax.plot(xs, zs, color="k", lw=0.8)
    ax.set_aspect("equal")
    if not dims:
        return
    x0, x1 = float(o.x[0]), float(o.x[-1])
    ztop, zbot = float(o.z_high.max()), float(o.z_low.min())
    rim_top = ztop - o.cup_depth
    pad = 0.06 * max(o.length, o.thickness)
    _dim(ax, (x0, ztop), (x0, zbot), f"{o.thickness:.3g}", offset=(-pad, 0), rotation=90)
    if o.has_band:  # a sphere or spheroid has no band, and no cups
        _dim(ax, (x1, rim_top), (x1, rim_top - o.band), f"band {o.band:.3g}", offset=(pad, 0), rotation=90)
        if o.cup_depth > 1e-6:
            xc = float(o.x[np.argmax(o.z_high)])
            ax.plot([x0, x1], [rim_top, rim_top], color="0.5", lw=0.4, ls=":")
            _dim(ax, (xc, rim_top), (xc, ztop), f"cup {o.cup_depth:.3g}", offset=(0, 0))
        if o.cup_depth_bottom > 1e-6 and f"{o.cup_depth_bottom:.3g}" != f"{o.cup_depth:.3g}":
            xc, rim_bot = float(o.x[np.argmin(o.z_low)]), rim_top - o.band
            ax.plot([x0, x1], [rim_bot, rim_bot], color="0.5", lw=0.4, ls=":")
            _dim(ax, (xc, zbot), (xc, rim_bot), f"cup {o.cup_depth_bottom:.3g}", offset=(0, 0))
    _scale_bar(ax, x0, zbot - 2.0 * pad, o.length)
    _panel_title(ax, "side profile")
    ax.margins(0.2)
    ax.set_axis_off()


def _convex(tablet: Tablet) -> bool:
    """Whether the (untrimmed) tablet is known to be convex, so that no two quads of its faces
    turned towards a viewer overlap on screen and every face can be drawn as one mesh in any
    order (:func:`_draw_view`, :func:`_draw_plan`).  Decided on exact data, not on samples:

    * an industry family: its nominal's :attr:`~tabletcad.families.sweep.SweepNominal.convex`
      (its surface lies within 1 µm of that nominal);
    * a tablet of revolution whose meridian section (its profiles through every patch, both
      sides of the axis) lies on the boundary of its convex hull to 1e-3 of its size (so any
      overlap is a sliver of a fraction of a pixel).
    """
    if not tablet.trim.whole:
        return False
    family_convex = getattr(tablet.nominal, "convex", None)  # a family's nominal knows (SweepNominal.convex)
    if family_convex is not None:
        return bool(family_convex)
    revs = tablet.revolution
    if revs is None:
        return False
    from scipy.spatial import ConvexHull

    u = np.linspace(0.0, 1.0, 129)
    M = np.concatenate([r.profile(u) for r in revs])  # (R, Z) along the chain of patches
    section = np.concatenate([M, M * [-1.0, 1.0]])  # the meridian section through the axis
    size = float(np.ptp(section, axis=0).max())
    hull = ConvexHull(section)
    # every point on the hull's boundary, to a thousandth of the size: the thesis's PDE shapes dip
    # a few micrometres inside theirs where their patches meet (a fraction of a pixel, whose
    # slivers of overlap no picture shows); a land that a cup rises from does not pass
    inside = -np.max(section @ hull.equations[:, :2].T + hull.equations[:, 2], axis=1)
    return bool(np.max(inside) <= 1e-3 * size)


def _graph_from_above(tablet: Tablet, convex: bool | None = None) -> bool:
    """Whether the faces turned up of the (untrimmed) tablet never overlap seen from above, so the
    plan can draw every face as one mesh: an industry family (a :class:`~tabletcad.families.sweep.SweepNominal`
    with lines and arcs, whose top face is a height over the inward distance from the outline,
    which every plan point has one of; its band's upward-turned strip, where it bulges, lies
    outside the rim), or a convex tablet (:func:`_convex`, or ``convex`` when already known)."""
    if not tablet.trim.whole:
        return False
    if getattr(tablet.nominal, "convex", None) is not None:
        return True
    return _convex(tablet) if convex is None else convex


def _meshes(ax, items) -> None:
    """Add ``(key, coordinates (ns, nt, 2), rgba (cells, 4))`` as one QuadMesh each, in order of key
    (matplotlib draws a mesh's cells in C, without a Path per quad)."""
    from matplotlib.collections import QuadMesh

    for _, xy, rgba in sorted(items, key=lambda it: it[0]):
        m = QuadMesh(xy, antialiased=False, linewidths=0.0, edgecolors="none")
        m.set_facecolor(rgba)
        ax.add_collection(m, autolim=False)


def _rgba(rgb: np.ndarray, seen: np.ndarray) -> np.ndarray:
    out = np.zeros((len(seen), 4))
    out[seen, :3] = rgb
    out[seen, 3] = 1.0
    return out


def _draw_plan(ax, tablet: Tablet, o: TabletOutline, grids, colour="#4e79a7", dims: bool = True,
               convex: bool | None = None) -> None:
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgb

    base = np.array(to_rgb(colour))
    outward = tablet.orientation
    graph = _graph_from_above(tablet, convex)
    polys, cols, depth, meshes = [], [], [], []
    for face, Y in grids:
        q = _quads(Y)
        n = cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]) * (face.sign * outward)
        n /= np.maximum(np.linalg.norm(n, axis=-1), 1e-300)[:, None]
        # seen from above: the faces turned up (outward normals; walls are edge-on, the
        # bottom lies under the top, whatever the grid's orientation)
        seen = n[:, 2] > 1e-3
        if not np.any(seen):
            continue
        lam = np.clip(n[seen] @ _LIGHT, 0.0, 1.0)
        rgb = np.clip(base[None, :] * (0.2 + 1.0 * lam[:, None] ** 2) + 0.05, 0, 1)
        if graph:  # the faces turned up never overlap in plan: one mesh each, lowest first
            meshes.append((float(q[seen][:, :, 2].mean()), Y[..., :2], _rgba(rgb, seen)))
            continue
        polys.append(q[seen][:, :, :2])
        cols.append(rgb)
        depth.append(q[seen][:, :, 2].mean(axis=1))
    _meshes(ax, meshes)
    if polys:
        order = np.argsort(np.concatenate(depth), kind="stable")  # painter: the top face drawn last
        # no data limits from the polygons: the plan outline drawn next spans the same extent
        ax.add_collection(PolyCollection(np.concatenate(polys)[order], facecolors=np.concatenate(cols)[order],
                                         linewidths=0, antialiased=False), autolim=False)
    for loop in (o.plan, *o.plan_holes):
        ax.plot(loop[:, 0], loop[:, 1], color="k", lw=0.8)
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
    _scale_bar(ax, float(lo[0]), float(lo[1]) - 2.5 * pad, max(o.length, o.width))
    _panel_title(ax, "plan")
    ax.margins(0.2)
    ax.set_axis_off()


def view_axes(elev: float, azim: float) -> np.ndarray:
    """Rows: the screen's right and up directions and the direction towards the viewer (unit
    vectors) of an orthographic view from elevation ``elev`` and azimuth ``azim`` (degrees,
    matplotlib's 3-D convention)."""
    e, a = np.radians(elev), np.radians(azim)
    towards = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    return np.stack([right, cross(towards, right), towards])


def _draw_view(ax, tablet: Tablet, grids, elev: float, azim: float, convex: bool | None = None) -> None:
    """The shaded view of the closed surface, drawn as 2-D polygons to scale: every quad of the
    face grids projected orthographically, those facing away culled (outward normals from
    the faces' orientation), the rest painted far to near, each with a two-sided Lambert
    shade; then the outer faces' boundary lines (seams, rims) where a quad beside them is seen."""
    from matplotlib import colormaps
    from matplotlib.collections import LineCollection, PolyCollection

    R = view_axes(elev, azim)
    colours = colormaps["tab10"]
    outward = tablet.orientation
    hollow = tablet.trim.w[0] > 0.0
    convex = _convex(tablet) if convex is None else convex
    polys, cols, depth, lines, meshes = [], [], [], [], []
    for face, Y in grids:
        q = _quads(Y)
        n = cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]) * (face.sign * outward)
        n /= np.maximum(np.linalg.norm(n, axis=-1), 1e-300)[:, None]
        seen = n @ R[2] > 0.0
        lam = np.abs(n @ _LIGHT)  # two-sided Lambert, light low from the upper left
        base = np.array(colours(face.patch % 10)[:3]) if face.kind == "w" else np.array([0.72, 0.72, 0.72])
        # squared Lambert: the few degrees a cup tilts its faces show as a clear gradient
        rgb = np.clip(base[None, :] * (0.2 + 1.0 * lam[seen, None] ** 2), 0.0, 1.0)
        if convex:  # the quads turned towards the viewer never overlap: one mesh a face, far to near
            if np.any(seen):
                S = Y @ R.T
                meshes.append((-float(S[..., 2].mean()), S[..., :2], _rgba(rgb, seen)))
        else:
            P = q[seen] @ R.T  # (k, 4, 3): screen x, screen y, depth
            polys.append(P[..., :2])
            depth.append(P[..., 2].mean(axis=1))
            cols.append(rgb)
        # the outer surface's edge rows (seams, rims): segment j where quad j beside it is seen,
        # which on a convex tablet is exactly where it is visible (a ring's inner wall, which
        # its outer wall may hide, gets none)
        if face.kind == "w" and not (hollow and face.sign < 0):
            grid_seen = seen.reshape(Y.shape[0] - 1, Y.shape[1] - 1)
            for row, k in ((Y[0], 0), (Y[-1], -1)):
                E = row[:, None, :] @ R[:2].T
                seg = np.concatenate([E[:-1], E[1:]], axis=1)
                lines.append(seg[grid_seen[k]])
    _meshes(ax, meshes)
    if polys:
        order = np.argsort(np.concatenate(depth))  # far to near
        ax.add_collection(PolyCollection(np.concatenate(polys)[order], facecolors=np.concatenate(cols)[order],
                                         edgecolors="none", linewidths=0.0, antialiased=False), autolim=False)
    ax.add_collection(LineCollection(np.concatenate(lines), colors="k", linewidths=0.5), autolim=False)
    pts = np.vstack([Y.reshape(-1, 3) for _, Y in grids]) @ R[:2].T
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.03 * float(np.max(hi - lo))
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")  # to scale: one mm is as long on screen in every direction
    # a picture, not a chart: the profile and plan beside it carry the axes and the dimensions
    ax.set_axis_off()


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

    ``tablet``: a :class:`Tablet` or anything with a ``.tablet`` (a :class:`~tabletcad.pipeline.model.TabletModel`).
    The 3-D view (from ``elev``, ``azim``, degrees) is an orthographic projection drawn as
    2-D polygons (:func:`_draw_view`): culled and sorted by depth here, which matplotlib's
    3-D axes did per polygon in Python at about half the picture's cost.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    tablet = _as_tablet(tablet)
    fig = Figure(figsize=(11.0, 4.0))
    FigureCanvasAgg(fig)  # no global backend: the figure owns its Agg canvas
    faces = tablet.faces()  # once: finding the shared edges evaluates the patches
    grids = _face_grids(tablet, nu, nv, faces)
    convex = _convex(tablet)  # once for both panels
    _draw_view(fig.add_subplot(131), tablet, grids, elev, azim, convex)
    o = _side_profile(tablet, 121, 65, 257, grids, faces)  # the view's grids: to a fraction of a pixel
    _draw_profile(fig.add_subplot(132), o)
    _draw_plan(fig.add_subplot(133), tablet, o, grids, convex=convex)
    fig.suptitle(title or f"{tablet.name} ({tablet.family}, {len(tablet.patches)} patches), mm", fontsize=10)
    fig.subplots_adjust(left=0.02, right=0.98, wspace=0.3)
    return fig


def tablets_figure(tablets: Sequence[Tablet], *, labels: Sequence[str] | None = None, nu: int = 25, nv: int = 73):
    """Side profiles (top row) and plans (bottom row) of several tablets at one scale (mm).

    ``tablets``: :class:`Tablet` objects or anything with a ``.tablet`` (a
    :class:`~tabletcad.pipeline.model.TabletModel`), in any mix.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    tablets = [_as_tablet(t) for t in tablets]
    k = len(tablets)
    if k == 0:
        raise ValueError("tablets_figure needs at least one tablet")
    labels = list(labels) if labels is not None else [t.name for t in tablets]
    fig = Figure(figsize=(2.6 * k + 0.6, 5.0))
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, k, squeeze=False, sharex="row", sharey="row")
    outlines = []
    for i, t in enumerate(tablets):
        faces = t.faces()
        grids = _face_grids(t, nu, nv, faces)
        o = _side_profile(t, 121, 65, 257, None, faces)
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
    save_figure(tablet_figure(tablet, **kw), buf, fmt="png", dpi=dpi, pil_kwargs=_PNG)
    return buf.getvalue()


#: zlib level 1: the same pixels (PNG is lossless) in a file ~20 % larger, encoded in a tenth of
#: the time of the default level (benchmarks/bench_plot.py)
_PNG = {"compress_level": 1}


#: the picture formats a path may ask for, by its suffix (matplotlib writes each)
PICTURE_SUFFIXES = (".png", ".svg", ".pdf")


def _picture_path(path: str | Path) -> Path:
    """``path`` as a :class:`Path` when its suffix names a picture format (:data:`PICTURE_SUFFIXES`), else a
    :class:`DesignError` (PNG bytes had been written under any name: ``x.pdf`` held a PNG)."""
    path = Path(path)
    if path.suffix.lower() not in PICTURE_SUFFIXES:
        raise DesignError("path", str(path), f"must end in {', '.join(PICTURE_SUFFIXES[:-1])} or {PICTURE_SUFFIXES[-1]}")
    return path


def _save(fig, path: Path, dpi: int) -> Path:
    fmt = path.suffix.lower()[1:]
    return save_figure(fig, path, fmt=fmt, dpi=dpi, **({"pil_kwargs": _PNG} if fmt == "png" else {}))


def plot_tablet(tablet: Tablet, path: str | Path, *, dpi: int = 110, **kw) -> Path:
    """Write the picture of :func:`tablet_figure` to ``path`` (written atomically), in the format its suffix
    names: ``.png``, ``.svg`` or ``.pdf``."""
    path = _picture_path(path)
    return _save(tablet_figure(tablet, **kw), path, dpi)


def plot_tablets(tablets: Sequence, path: str | Path, *, dpi: int = 110, **kw) -> Path:
    """Write :func:`tablets_figure` (several tablets, or models, at one scale) to ``path``: ``.png``, ``.svg`` or
    ``.pdf`` by its suffix."""
    path = _picture_path(path)
    return _save(tablets_figure(tablets, **kw), path, dpi)
