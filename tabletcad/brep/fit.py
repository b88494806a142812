"""The interpolation fit of parametric surfaces by B-spline surfaces (numpy only).

:func:`fit_surface` interpolates a parametric surface ``f(u, v) -> (..., 3)``
(``u`` in [0, 1] clamped, ``v`` periodic with period ``2 pi``) at the
surface's own parameter values, so the B-spline parametrisation matches the
patch's, and refines the grid until the deviation measured on a much denser
grid is within tolerance.  :func:`fit_patches` fits a chain of patches with a
common ``v`` grid so that neighbouring patches get bit-identical boundary rows.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from tabletcad.brep.knots import clamped_interp_knots, normalise_breaks, periodic_knots
from tabletcad.brep.surface import BSplineSurfaceData
from tabletcad.errors import GeometryError
from tabletcad.geometry.vectors import norm3

__all__ = ["PatchFunction", "SurfaceFit", "SurfaceFunction", "chain_breakpoints", "fit_patches", "fit_surface"]


SurfaceFunction = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class SurfaceFit:
    """Result of :func:`fit_surface`: the B-spline plus the measured deviation.

    ``max_deviation`` is the largest distance |S(u, v) - f(u, v)| (same
    parameters) over a check grid ``check_factor`` times denser than the fit
    grid in each direction, which includes the points midway between samples;
    for a fit that :func:`fit_patches` solved again with a neighbour's boundary
    row, that figure of the first fit plus the largest pole change (a bound).
    ``u_samples``/``v_samples`` are the interpolation parameters.
    """

    surface: BSplineSurfaceData
    max_deviation: float
    rms_deviation: float
    tol: float
    nu: int
    nv: int
    iterations: int
    check_points: int
    pole_u0: bool
    pole_u1: bool
    seconds: float
    u_samples: np.ndarray = field(repr=False)
    v_samples: np.ndarray = field(repr=False)
    v_breaks: tuple[float, ...] = ()
    samples: np.ndarray | None = field(default=None, repr=False)  # f on the u x v samples, as evaluated

    @property
    def poles(self) -> tuple[int, int]:
        """Number of poles ``(u, v)`` of the surface (``nv`` counts v spans, not poles, when
        there are breakpoints of multiplicity > 1)."""
        return self.surface.shape

    @property
    def ok(self) -> bool:
        return self.max_deviation <= self.tol


def _eval_f(f: SurfaceFunction, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``f`` on the tensor grid ``u x v``; uses ``f.evaluate_grid(u, v)`` when ``f`` has one
    (e.g. a PDE patch: matrix products instead of point-wise series, ~25x faster)."""
    grid = getattr(f, "evaluate_grid", None)
    shape = (np.size(u), np.size(v))
    if grid is not None:
        X = np.asarray(grid(np.asarray(u, dtype=float), np.asarray(v, dtype=float)), dtype=float)
    else:
        U, V = np.meshgrid(u, v, indexing="ij")
        X = np.asarray(f(U, V), dtype=float)
    X = np.broadcast_to(X, shape + (3,))
    if not np.all(np.isfinite(X)):
        raise GeometryError("surface function returned non-finite values", f)
    return np.array(X)


def _eval_f_components(f: SurfaceFunction, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``f`` on the tensor grid ``u x v``, components first: ``(3, len(u), len(v))`` mm.  A function
    with ``evaluate_grid_components`` (a PDE patch: :class:`PatchFunction`) gives that layout straight
    from its matrix products, with no transposed copy; any other is evaluated by :func:`_eval_f` and
    viewed so."""
    # (not ``grid_components``: BSplineSurfaceData's method of that name gives points and derivatives)
    grid = getattr(f, "evaluate_grid_components", None)
    if grid is None:
        return np.moveaxis(_eval_f(f, u, v), -1, 0)
    X = np.asarray(grid(np.asarray(u, dtype=float), np.asarray(v, dtype=float)), dtype=float)
    if X.shape != (3, np.size(u), np.size(v)):
        raise GeometryError(f"evaluate_grid_components returned shape {X.shape}", f)
    if not np.all(np.isfinite(X)):
        raise GeometryError("surface function returned non-finite values", f)
    return X


def _solve_poles(
    D: np.ndarray, u: np.ndarray, v: np.ndarray, u_degree: int, v_degree: int, v_knots, v_mults, u_periodic: bool
):
    """Poles interpolating grid data ``D[i, j] = f(u[i], v[j])`` (tensor-product collocation)."""
    nu, nv = D.shape[:2]
    if u_periodic:
        raise NotImplementedError("periodic u is not supported")
    u_knots, u_mults = clamped_interp_knots(u, u_degree)
    # only the knots of the surface to be are asked for (its collocation matrices): set, not validated (the
    # poles come out of these knots, and the surface made of them is validated)
    proto = object.__new__(BSplineSurfaceData)
    for name, value in (("poles", np.broadcast_to(0.0, (nu, nv, 3))), ("u_knots", np.asarray(u_knots, dtype=float)),
                        ("u_mults", np.asarray(u_mults, dtype=int)), ("v_knots", np.asarray(v_knots, dtype=float)),
                        ("v_mults", np.asarray(v_mults, dtype=int)), ("u_degree", int(u_degree)),
                        ("v_degree", int(v_degree)), ("u_periodic", False), ("v_periodic", True)):
        object.__setattr__(proto, name, value)
    Bu = proto.collocation("u", u)
    Bv = proto.collocation("v", v)
    # along u: the end rows of a clamped interpolant equal the data exactly, so
    # solve only for the interior rows (keeps boundary rows bit-identical to the data).
    X = np.empty_like(D)
    X[0] = D[0]
    X[-1] = D[-1]
    if nu > 2:
        rhs = D[1:-1].reshape(nu - 2, -1) - np.outer(Bu[1:-1, 0], D[0].ravel()) - np.outer(Bu[1:-1, -1], D[-1].ravel())
        X[1:-1] = np.linalg.solve(Bu[1:-1, 1:-1], rhs).reshape(nu - 2, nv, 3)
    # along v (periodic): Bv P_i = X_i for every row i
    rhs = X.transpose(1, 0, 2).reshape(nv, -1)
    P = np.linalg.solve(Bv, rhs).reshape(nv, nu, 3).transpose(1, 0, 2)
    return u_knots, u_mults, np.ascontiguousarray(P)


def _pole_point(row: np.ndarray, pole_tol: float) -> np.ndarray | None:
    centre = row.mean(axis=0)
    if np.max(norm3(row - centre)) <= pole_tol:
        return centre
    return None


def _build(
    f: SurfaceFunction,
    nu: int,
    nv: int,
    u_degree: int,
    v_degree: int,
    pole_tol: float,
    u_range: tuple[float, float],
    boundary_rows: tuple[np.ndarray | None, np.ndarray | None] = (None, None),
    v_breaks=None,
    break_mult: int | None = None,
):
    u = np.linspace(u_range[0], u_range[1], nu)
    v_knots, v_mults, v = periodic_knots(nv, v_degree, v_breaks, break_mult)
    D = _eval_f(f, u, v)
    data, flags, D = _interpolate(D.copy(), D, u, v, u_degree, v_degree, pole_tol, boundary_rows, v_knots, v_mults)
    return data, u, v, flags, D


def _interpolate(D, raw, u, v, u_degree, v_degree, pole_tol, boundary_rows, v_knots, v_mults):
    """The B-spline interpolating the samples ``D`` (modified: shared boundary rows put in,
    collapsed rows made one point); returns ``(data, pole flags, raw)``."""
    poles_flags = []
    for k, r in ((0, 0), (-1, 1)):
        if boundary_rows[r] is not None:
            D[k] = boundary_rows[r]
        p = _pole_point(D[k], pole_tol)
        if p is not None:
            D[k] = p  # a collapsed boundary becomes exactly one point
        poles_flags.append(p is not None)
    u_knots, u_mults, P = _solve_poles(D, u, v, u_degree, v_degree, v_knots, v_mults, False)
    # interpolating constant data along v gives the constant back up to round-off: make it exact
    for k, flag in ((0, poles_flags[0]), (-1, poles_flags[1])):
        if flag:
            P[k] = D[k][0]
    data = BSplineSurfaceData(P, u_knots, u_mults, v_knots, v_mults, u_degree, v_degree, False, True)
    return data, poles_flags, raw


def _deviation(f: SurfaceFunction, data: BSplineSurfaceData, u: np.ndarray, v: np.ndarray, factor: int):
    """Errors on a grid ``factor`` x denser (includes midpoints between samples)."""
    nu = u.size
    uc = np.linspace(u[0], u[-1], factor * (nu - 1) + 1)
    # ``factor`` points per gap between consecutive (periodic) samples; column ``factor * j`` is sample j
    vs = np.concatenate([v, [v[0] + math.tau]])
    vc = (vs[:-1, None] + (np.arange(factor) / factor)[None, :] * np.diff(vs)[:, None]).ravel()
    # components first (3, len(uc), len(vc)), as the products make them: no transposed copies, and
    # |D| from three contiguous planes (the squares summed x, z, y: the einsum over the last axis this
    # replaced added them in that order, so the figures stay the same to the bit)
    D = data.evaluate_grid(uc, vc, components=True)
    D -= _eval_f_components(f, uc, vc)
    E = np.sqrt(D[0] * D[0] + D[2] * D[2] + D[1] * D[1])
    # split: points on sample v-lines (pure u-interpolation error) and on sample u-lines
    err_u = float(E[:, ::factor].max())
    err_v = float(E[::factor, :].max())
    return float(E.max()), float(np.sqrt(np.mean(E**2))), err_u, err_v, E.size


def fit_surface(
    f: SurfaceFunction,
    u_degree: int = 3,
    v_degree: int = 3,
    nu: int = 17,
    nv: int = 32,
    periodic_v: bool = True,
    tol: float = 1e-4,
    *,
    max_nu: int = 400,
    max_nv: int = 512,
    max_iterations: int = 12,
    check_factor: int = 4,
    pole_tol: float = 1e-9,
    u_range: tuple[float, float] = (0.0, 1.0),
    fixed_nv: bool = False,
    boundary_rows: tuple[np.ndarray | None, np.ndarray | None] = (None, None),
    v_breaks: Sequence[float] | None = None,
    v_break_mult: int | None = None,
    name: str = "surface",
    raise_on_failure: bool = True,
) -> SurfaceFit:
    """Interpolate ``f`` by a B-spline (clamped in ``u``, periodic in ``v``) within ``tol``.

    ``f(u, v)`` must broadcast its arguments and return ``(..., 3)``.  The
    surface is sampled on a uniform ``nu x nv`` grid of its own parameters,
    poles are obtained by solving the 1-D collocation systems along ``u`` then
    along ``v``, and the grid is refined (per direction, from the measured
    error and the ``h^(p+1)`` convergence rate) until the maximum deviation on a
    ``check_factor``-times denser grid is ``<= tol`` (same unit as ``f``, mm).
    A boundary row whose points agree within ``pole_tol`` is a pole: its
    poles are set to exactly one point.  ``fixed_nv`` keeps ``nv`` unchanged
    (used by :func:`fit_patches` to share boundary rows); ``boundary_rows``
    overrides the sampled data of the ``u`` min / max rows.

    ``v_breaks``: values of ``v`` where ``f`` is not smooth in ``v`` (e.g. the
    junctions of an outline's arcs and lines, where the surface is only C1).
    They become knots of multiplicity ``v_break_mult`` (default
    ``v_degree - 1``, C1; ``v_degree`` gives C0) with uniform spans between
    them and Greville interpolation points (see :func:`periodic_knots`), so
    every smooth piece converges at the full order ``h^(v_degree+1)``.  ``nv``
    then counts knot spans rather than poles.

    Raises :class:`GeometryError` naming ``name`` and the deviation if the
    tolerance cannot be met within ``max_nu``/``max_nv``/``max_iterations``
    (unless ``raise_on_failure`` is false).
    """
    if not periodic_v:
        raise NotImplementedError("fit_surface only supports periodic v (a closed patch)")
    if tol <= 0 or not math.isfinite(tol):
        raise ValueError(f"tol = {tol} is not allowed: must be > 0")
    t0 = time.perf_counter()
    nu = max(int(nu), u_degree + 1)
    nv = max(int(nv), v_degree + 1)
    breaks = normalise_breaks(v_breaks)
    best = None
    for it in range(1, max_iterations + 1):
        data, u, v, flags, raw = _build(
            f, nu, nv, u_degree, v_degree, pole_tol, u_range, boundary_rows, breaks, v_break_mult
        )
        dmax, drms, err_u, err_v, npts = _deviation(f, data, u, v, check_factor)
        best = SurfaceFit(
            data, dmax, drms, tol, nu, nv, it, npts, flags[0], flags[1], time.perf_counter() - t0, u, v,
            tuple(float(b) for b in breaks), raw,
        )
        if dmax <= tol:
            return best
        # refine: error ~ h^(p+1); aim at 0.4 tol (error on sample v-lines is pure
        # u-interpolation error and vice versa)
        target = 0.4 * tol
        ref_u, ref_v = err_u > target, err_v > target and not fixed_nv
        if not (ref_u or ref_v):
            ref_u, ref_v = True, not fixed_nv
        new_nu, new_nv = nu, nv
        if ref_u:
            ratio = (err_u if err_u > target else dmax) / target
            new_nu = int(math.ceil((nu - 1) * min(max(ratio ** (1.0 / (u_degree + 1)), 1.25), 3.0))) + 1
        if ref_v:
            ratio = (err_v if err_v > target else dmax) / target
            new_nv = int(math.ceil(nv * min(max(ratio ** (1.0 / (v_degree + 1)), 1.25), 3.0)))
        new_nu, new_nv = min(new_nu, max_nu), min(new_nv, max_nv)
        if (new_nu, new_nv) == (nu, nv):
            break
        nu, nv = new_nu, new_nv
    assert best is not None
    if raise_on_failure:
        raise GeometryError(
            f"B-spline fit of {name} misses tolerance: max deviation {best.max_deviation:.3g} mm > "
            f"tol {tol:.3g} mm with {best.surface.shape[0]} x {best.surface.shape[1]} poles",
            best,
        )
    return best


def fit_patches(
    functions: Sequence[SurfaceFunction],
    tol: float = 1e-4,
    *,
    names: Sequence[str] | None = None,
    u_degree: int = 3,
    v_degree: int = 3,
    nu: int = 17,
    nv: int = 32,
    share_tol: float = 1e-9,
    v_breaks: Sequence[float] | None = None,
    v_break_mult: int | None = None,
    **kwargs,
) -> list[SurfaceFit]:
    """Fit a chain of patches (patch ``j``'s ``u=1`` curve is patch ``j+1``'s ``u=0`` curve).

    All patches get the same periodic ``v`` knots, and a shared boundary row is
    sampled once and reused, so neighbours have bit-identical boundary poles
    (and sew without gaps).  A closed chain (a ring: last ``u=1`` equals first
    ``u=0``) is detected and shared too.  Raises :class:`GeometryError` naming
    the patch if a fit misses ``tol`` or if neighbouring boundaries disagree by
    more than ``share_tol``.

    ``v_breaks`` (see :func:`fit_surface`) must be the union of the breakpoints
    of the whole chain: every patch gets the same breakpoint knots, which keeps
    the v knot vectors, hence the shared boundary rows, identical.
    """
    functions = list(functions)
    n = len(functions)
    names = list(names) if names is not None else [f"patch {j}" for j in range(n)]
    # pass 1: independent fits to find the v resolution each patch needs
    kwargs.update(v_breaks=v_breaks, v_break_mult=v_break_mult)
    first = [
        fit_surface(fj, u_degree, v_degree, nu, nv, True, tol, name=names[j], **kwargs)
        for j, fj in enumerate(functions)
    ]
    nv_common = max(fit.nv for fit in first)
    _, _, v = periodic_knots(nv_common, v_degree, v_breaks, v_break_mult)
    zeros = np.zeros(1)
    rows_end = [_eval_f(fj, np.array([1.0]), v)[0] for fj in functions]
    rows_start = [_eval_f(fj, zeros, v)[0] for fj in functions]
    shared: list[list[np.ndarray | None]] = [[None, None] for _ in range(n)]
    pairs = [(j, j + 1) for j in range(n - 1)]
    if n > 1 and np.max(norm3(rows_end[-1] - rows_start[0])) <= share_tol:
        pairs.append((n - 1, 0))
    for a, b in pairs:
        gap = float(np.max(norm3(rows_end[a] - rows_start[b])))
        if gap > share_tol:
            raise GeometryError(
                f"{names[a]} (u=1) and {names[b]} (u=0) do not share their boundary curve: gap {gap:.3g} mm",
                (functions[a], functions[b]),
            )
        shared[a][1] = rows_end[a]
        shared[b][0] = rows_end[a]
    fits = []
    for j, fj in enumerate(functions):
        if first[j].nv == nv_common and all(r is None for r in shared[j]):
            fits.append(first[j])
            continue
        again = _with_rows(first[j], shared[j], v, u_degree, v_degree, kwargs.get("pole_tol", 1e-9))
        if again is not None:
            fits.append(again)
            continue
        fits.append(
            fit_surface(
                fj,
                u_degree,
                v_degree,
                first[j].nu,
                nv_common,
                True,
                tol,
                fixed_nv=True,
                boundary_rows=(shared[j][0], shared[j][1]),
                name=names[j],
                **kwargs,
            )
        )
    # The shared rows were solved from identical data with the identical periodic
    # matrix; copy them so that they are bit-identical whatever LAPACK does.
    for a, b in pairs:
        pa, pb = fits[a].surface.poles, fits[b].surface.poles
        diff = float(np.max(np.abs(pa[-1] - pb[0])))
        if diff > max(share_tol, 1e-12):
            raise GeometryError(f"{names[a]} and {names[b]}: shared boundary poles differ by {diff:.3g}", fits)
        poles = np.array(pb)
        poles[0] = pa[-1]
        fits[b] = replace(fits[b], surface=replace(fits[b].surface, poles=poles))
    return fits


def _with_rows(fit: SurfaceFit, rows, v: np.ndarray, u_degree: int, v_degree: int, pole_tol: float):
    """``fit`` interpolated again with its shared boundary ``rows`` put into its own samples,
    without evaluating the surface again, or None if that cannot be certified within the
    tolerance (then :func:`fit_surface` refits and measures).

    The poles are those :func:`fit_surface` computes from the same samples, bit for bit.  Its
    deviation is bounded by the first fit's measured one plus the largest pole change: a
    B-spline surface's basis functions are non-negative and sum to one, so the surfaces of
    two pole sets differ nowhere by more than their poles do."""
    if fit.samples is None or fit.v_samples.shape != v.shape or not np.array_equal(fit.v_samples, v):
        return None
    s = fit.surface
    data, flags, _ = _interpolate(fit.samples.copy(), fit.samples, fit.u_samples, v, u_degree, v_degree, pole_tol,
                                  tuple(rows), s.v_knots, s.v_mults)
    if data.shape != s.shape:
        return None
    moved = float(np.max(norm3(data.poles - s.poles)))
    bound = fit.max_deviation + moved
    if bound > fit.tol:
        return None
    return replace(fit, surface=data, max_deviation=bound, rms_deviation=fit.rms_deviation + moved,
                   pole_u0=flags[0], pole_u1=flags[1])


class PatchFunction:
    """``f(u, v) = patch.evaluate(u, v)``; keeps the patch's ``evaluate_grid`` (tensor grids by
    matrix products), which :func:`fit_surface` uses when present."""

    def __init__(self, patch) -> None:
        from tabletcad.geometry.patch import PDEPatch  # (here: brep.fit alone does not load the patches)

        self.patch = patch
        if hasattr(patch, "evaluate_grid"):
            self.evaluate_grid = lambda u, v: np.asarray(patch.evaluate_grid(u, v))
        if isinstance(patch, PDEPatch):  # the same grid, components first (no transposed copy)
            self.evaluate_grid_components = lambda u, v: patch.evaluate_grid(u, v, components=True)

    def __call__(self, u, v) -> np.ndarray:
        return np.asarray(self.patch.evaluate(u, v))


def chain_breakpoints(patches) -> np.ndarray:
    """Union (sorted, in [0, 2 pi), values within 1e-9 merged) of the ``breakpoints()`` of the
    patches that have them."""
    pts = [np.asarray(p.breakpoints(), dtype=float).ravel() for p in patches if hasattr(p, "breakpoints")]
    pts = [b for b in pts if b.size]
    if not pts:
        return np.zeros(0)
    return normalise_breaks(np.concatenate(pts))
