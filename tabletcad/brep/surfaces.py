"""The faces of a tablet's solid as surface functions, ready for the B-spline fit (numpy only).

Every face of the solid is a surface ``f(s, v) -> (..., 3)`` (mm) over ``s in [0, 1]`` and
periodic ``v``, and consecutive faces share their boundary curves (a chain).  An ordinary
tablet's faces are its patches.  A hollow tablet (``trim.w[0] > 0``, e.g. the ring) is the
closed chain outer wall -> end face at ``u = 1`` -> inner wall (reversed) -> end face at
``u = 0``.  A cut-away (``[trim] v``) is one closed chain over ``theta``.  :func:`fit_options`
holds the fit's settings for every kernel: the OCP layer (:mod:`tabletcad.cad.tablet_solid`)
and the FreeCAD workbench both fit these functions with :func:`tabletcad.brep.fit.fit_patches`.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from tabletcad.errors import GeometryError
from tabletcad.geometry.tablet import Tablet, solid_map

__all__ = ["SurfaceFunction", "tablet_surface_functions", "tablet_profiles", "cutaway_surface_functions",
           "tablet_breakpoints", "fit_options"]

SurfaceFunction = Callable[[np.ndarray, np.ndarray], np.ndarray]


def tablet_surface_functions(tablet: Tablet) -> tuple[list[SurfaceFunction], list[str]]:
    """Surface functions ``f(s, v) -> (..., 3)`` (mm), ``s ∈ [0, 1]``, forming a chain.

    Raises :class:`GeometryError` for tablets trimmed in ``u`` or ``v``.
    """
    t = tablet.trim
    if t.u != (0.0, 1.0) or not t.full_v:
        raise GeometryError(
            f"{tablet.name}: a tablet trimmed in u or v (a cut-away view) is not a chain of patch faces; "
            "tabletcad build and TabletModel.to_occ make its solid (tabletcad.cad.stage.cutaway_solid), "
            "the FreeCAD workbench and the FE commands do not",
            tablet,
        )
    w0, w1 = t.w
    names = [p.name or f"patch {j}" for j, p in enumerate(tablet.patches)]
    if w0 == 0.0 and w1 == 1.0:
        from tabletcad.brep.fit import PatchFunction  # keeps the patches' fast evaluate_grid

        return [PatchFunction(p) for p in tablet.patches], names
    if len(tablet.patches) != 1:
        raise GeometryError(f"{tablet.name}: hollow (w-trimmed) solids are exported for one-patch tablets only", tablet)
    p = tablet.patches[0]

    def lerp(a: float, b: float, s: np.ndarray) -> np.ndarray:
        return a + (b - a) * s

    funcs: list[SurfaceFunction] = [
        lambda s, v: solid_map(p, s, v, np.full(np.broadcast(s, v).shape, w1)),  # outer wall u: 0 -> 1
        lambda s, v: solid_map(p, np.ones(np.broadcast(s, v).shape), v, lerp(w1, w0, np.asarray(s))),  # end u=1
        lambda s, v: solid_map(p, 1.0 - np.asarray(s), v, np.full(np.broadcast(s, v).shape, w0)),  # inner wall
        lambda s, v: solid_map(p, np.zeros(np.broadcast(s, v).shape), v, lerp(w0, w1, np.asarray(s))),  # end u=0
    ]
    base = names[0]
    return funcs, [f"{base} outer wall", f"{base} end u=1", f"{base} inner wall", f"{base} end u=0"]


def cutaway_surface_functions(tablet: Tablet) -> tuple[list[SurfaceFunction], np.ndarray]:
    """Surface functions ``f(s, θ)`` of a cut-away (``[trim] v = [v0, v1]``, ``w = [0, 1]``) and their
    breakpoints in ``θ``: one closed chain, as the whole tablet's.

    For each ``u`` the boundary of the solid map's ``(v, w)`` rectangle is walked once round
    ``θ ∈ [0, 2π)``: the outer surface ``w = 1`` from ``v0`` to ``v1``, the cut face ``v = v1``
    from ``w = 1`` in to the spine, then the cut face ``v = v0`` back out (the leg ``w = 0`` is the
    spine itself, a point for each ``u``).  Each cut face is the ruled surface
    ``A0(u) + w (X(u, v) - A0(u))`` of eq 4.12, whatever its shape; the corners and the
    outline's joins inside ``[v0, v1]`` are the breakpoints (C0 knots).  The legs share
    ``θ`` in proportion to their lengths for a round tablet (``v1 - v0`` : 1 : 1).
    """
    v0, v1 = tablet.trim.v
    span = v1 - v0
    ta = 2.0 * np.pi * span / (span + 2.0)
    tb = ta + 0.5 * (2.0 * np.pi - ta)

    def make(p):
        def f(s, th):
            s, th = np.broadcast_arrays(np.asarray(s, float), np.mod(np.asarray(th, float), 2.0 * np.pi))
            v = np.where(th < ta, v0 + span * th / ta, np.where(th < tb, v1, v0))
            w = np.where(th < ta, 1.0, np.where(th < tb, 1.0 - (th - ta) / (tb - ta), (th - tb) / (2.0 * np.pi - tb)))
            return solid_map(p, s, v, w)
        return f

    from tabletcad.brep.fit import chain_breakpoints

    breaks = [0.0, ta, tb]
    for b in chain_breakpoints(tablet.patches):
        vb = v0 + np.mod(b - v0, 2.0 * np.pi)
        if v0 < vb < v1:
            breaks.append((vb - v0) / span * ta)
    return [make(p) for p in tablet.patches], np.array(sorted(breaks))


def tablet_breakpoints(tablet: Tablet) -> np.ndarray:
    """Union of the ``v`` breakpoints of the tablet's patches (sorted, in [0, 2π)).

    Every face of the solid (also the walls and end faces of a hollow tablet,
    which share the patch's ``v``) is fitted with breakpoint knots at all of
    them, so that the chain keeps one common ``v`` knot vector.
    """
    from tabletcad.brep.fit import chain_breakpoints

    return chain_breakpoints(tablet.patches)


def fit_options(tablet: Tablet, **kwargs: Any) -> dict[str, Any]:
    """Keyword arguments of :func:`tabletcad.brep.fit.fit_patches` for the tablet's chain.

    One place for every kernel (this OCP layer and the FreeCAD workbench):
    quintic B-splines - 17 x 32 poles already fit the thesis's tablets to ~3e-8
    mm, where cubics need ~4x the poles for 1e-5 mm (and leave a 1e-6 volume
    bias); knots of full multiplicity at the outline breakpoints, where the
    surface may be only C0 (a cup swept over an offset outline whose corner
    collapses) and where a slit is cut (:mod:`tabletcad.brep.slit`).  ``kwargs``
    override the defaults.
    """
    kwargs.setdefault("u_degree", 5)
    kwargs.setdefault("v_degree", 5)
    kwargs.setdefault("v_break_mult", kwargs["v_degree"])
    kwargs.setdefault("v_breaks", tablet_breakpoints(tablet))
    return kwargs


def tablet_profiles(tablet: Tablet) -> tuple[list, list[str]] | None:
    """The profiles ``f(s) -> (R, Z)`` (mm) of the faces of a tablet of revolution, or None.

    Each face of :func:`tablet_surface_functions` (the patches, or the walls and end faces
    of a hollow tablet) is then a surface of revolution about the z axis
    (:attr:`Tablet.revolution <tabletcad.geometry.tablet.Tablet.revolution>`); its profile is
    its meridian at plan angle 0, where ``y = 0`` and ``x = R``.  None for a tablet that is
    not of revolution; raises like :func:`tablet_surface_functions` for trimmed ones.
    """
    revs = tablet.revolution
    if revs is None:
        return None
    funcs, names = tablet_surface_functions(tablet)
    v0 = [r.v_of_angle(0.0) for r in revs]
    if len(funcs) != len(revs):  # the walls and ends of a hollow one-patch tablet
        v0 = v0[:1] * len(funcs)

    def meridian(f, v):
        return lambda s: np.asarray(f(np.asarray(s, dtype=float), np.full(np.shape(s), v)))[..., [0, 2]]

    return [meridian(f, v) for f, v in zip(funcs, v0)], names
