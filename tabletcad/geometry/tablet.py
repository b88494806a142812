"""Tablets: ordered PDE patches sharing boundary curves, and their solids.

A :class:`Tablet` is a chain of :class:`~tabletcad.geometry.patch.PDEPatch` objects in
which patch ``j``'s curve at ``u = 1`` is patch ``j + 1``'s curve at ``u = 0``
(C0 by construction, thesis section 3.4.1).  Each patch also defines a solid
``X(u, v, w) = A0(u) + w (X(u, v) - A0(u))``, ``w ∈ [0, 1]`` (eq 4.12),
filling the region between its spine and its surface; the tablet's solid is
the union of the patch solids.  A :class:`Trim` restricts ``u``, ``v`` and
``w`` (the thesis's cut-away views; ``w ∈ [0.5, 1]`` makes the ring tablet).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace
from typing import Any, Callable

import numpy as np

from tabletcad.errors import DesignError, check_range
from tabletcad.geometry.patch import PDEPatch
from tabletcad.geometry.revolution import profile_extreme
from tabletcad.readonly import TableDict
from tabletcad.tolerance import DEFAULT, Tolerances
from tabletcad.geometry.vectors import clip, cross_first, einsum, linspace, norm3, points_last
from tabletcad.geometry.quadrature import gauss_legendre

#: Trapezoidal points in ``v`` for the integrals of a surface of revolution, whose integrands
#: (``X·n``, ``|n|``, the solid map's Jacobian) are the same on every meridian.
_REVOLUTION_NV = 4
#: the plan's Newton polish takes a step only when it predicts a gain above this fraction of r² (rounding)
_POLISH_GAIN = 1e-14
#: the extents' zoom stops once its grid spans at most this much each side in ``u`` and ``v``, or ends with
#: a Newton step (:meth:`Tablet._newton_finish`) once it spans at most ``_NEWTON_FINISH``
_ZOOM_STOP = 1e-6
_NEWTON_FINISH = 1e-3

#: the sort of a cut-away's fan angles (runs of increasing or decreasing angles, one per line): numpy 2's
#: vectorised quicksort took 0.4 times the time of its timsort ("stable"), numpy 1.24's quicksort twice
#: the time (the same sorted values either way)
_ANGLE_SORT = "quicksort" if np.lib.NumpyVersion(np.__version__) >= "2.0.0" else "stable"

__all__ = ["Band", "Trim", "Tablet", "Face", "solid_map"]



def _monotone_pieces(psi: np.ndarray, x: np.ndarray, y: np.ndarray):
    """The runs of a polyline (polar angles ``psi``, points ``x, y``) on which the angle keeps its
    direction, each as ``(psi, x, y)`` with ``psi`` increasing (a pause of the angle at a turn
    belongs to the run before it)."""
    if psi.size < 2:
        return []
    d = np.sign(np.diff(psi))
    if (d == 0.0).any():  # carry the last direction over pauses, so that a turn through one is seen
        nz = np.flatnonzero(d)
        if not nz.size:
            return []
        d = d[nz][np.clip(np.searchsorted(nz, np.arange(d.size), "right") - 1, 0, None)]
    turns = np.flatnonzero(d[1:] != d[:-1]) + 1
    out = []
    for a, b in zip([0, *turns.tolist()], [*turns.tolist(), d.size]):
        q, px, py = psi[a:b + 1], x[a:b + 1], y[a:b + 1]
        if q[-1] < q[0]:
            q, px, py = q[::-1], px[::-1], py[::-1]
        out.append((q, px, py))
    return out


def _unwrap(p: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """``numpy.unwrap(p)`` of angles ``p`` (rad) whose steps' sizes ``|diff(p)|`` are ``steps``: when no step
    reaches π (a run of a fan's angles nearly always) its corrections are all zero and it returns
    ``p[1:] + 0.0`` after ``p[0]``, which this does without its dozen passes over the run (the same numbers)."""
    if float(steps.max()) >= math.pi:
        return np.unwrap(p)
    up = p + 0.0
    up[0] = p[0]
    return up


def _cover(env: np.ndarray, grid: np.ndarray, cs: tuple[np.ndarray, np.ndarray], q: np.ndarray, px: np.ndarray,
           py: np.ndarray, block: int = 16, *, span: tuple[int, int] | None = None,
           r2: np.ndarray | None = None) -> None:
    """Raise ``env`` (radii at the increasing angles ``grid``, whose cosines and sines are ``cs``) to the
    fan of one monotone piece of a polyline (:func:`_monotone_pieces`): the triangles from the centre
    over its chords, nothing outside the angles it spans (in place).

    The angle ``g`` falls on the chord ``k`` with ``q[k] <= g < q[k + 1]`` (the last chord keeps its end).
    The chords go by ``block``: where ``env`` already reaches the farthest of a block's points at every
    angle the block spans, its fan raises nothing there (a chord's points are never farther than its
    ends) and those angles are passed over — on a cut-away's cup lines, inside the band's, nearly all.  A
    piece whose farthest point ``env`` reaches at every angle it spans is passed over whole before the
    blocks are formed (then no block is live: the same result; with the pieces outside the grid, 35,000 of
    the 42,000 calls of ``tests/test_core_plan_cutaway.py``'s convergence cases had ended there; the plan
    area now leaves the pieces outside the grid out before it calls this).

    ``span``, the indices ``(s0, s1)`` of the angles the piece spans (``grid[s0:s1]``, the ``searchsorted``
    of ``q[0]`` on the left and ``q[-1]`` on the right), and ``r2``, the squared radii ``px² + py²`` (mm²),
    may be given when the caller has them (computed for many pieces at once, or once for copies shifted by
    2π): they are what this function would compute.
    """
    if span is None:
        span = (int(np.searchsorted(grid, q[0], "left")), int(np.searchsorted(grid, q[-1], "right")))
    s0, s1 = span
    if s1 <= s0:
        return
    if r2 is None:
        r2 = px * px + py * py
    low = float(env[s0:s1].min())
    if low * low >= float(r2.max()):  # the envelope already reaches every point at every angle: no block is live
        return
    n = q.size
    first = np.arange(0, n - 1, block)  # block j: the chords first[j] .. first[j + 1] - 1
    reach2 = np.maximum(np.maximum.reduceat(r2, first), r2[np.append(first[1:], n - 1)])
    # block j: the angles G[j] .. G[j + 1] - 1
    G = np.concatenate(([s0], np.searchsorted(grid, q[first[1:]], "left"), [s1]))
    lo = np.minimum.reduceat(env, np.minimum(G[:-1], env.size - 1))
    live = (G[1:] > G[:-1]) & ~(lo * lo >= reach2)
    if not live.any():
        return
    # the live blocks' chords, each with the run of angles that falls on it: angle index i falls on chord k
    # when q[k] <= grid[i] < q[k + 1], i.e. S[k] <= i < S[k + 1] with S[k] = #(grid < q[k]); a block's first
    # S is its G, its last chord's run ends at the block's end (the piece's last chord keeps its end)
    j = np.flatnonzero(live)
    nk = np.minimum(first[j] + block, n - 1) - first[j]
    ck = np.repeat(first[j] - np.cumsum(nk) + nk, nk) + np.arange(int(nk.sum()))
    S = np.searchsorted(grid, q[ck], "left")
    last = np.cumsum(nk) - 1
    S_next = np.empty_like(S)
    S_next[:-1] = S[1:]
    S_next[last] = G[j + 1]
    cnt = S_next - S
    gi = np.repeat(S - np.cumsum(cnt) + cnt, cnt) + np.arange(int(cnt.sum()))
    # each chord's terms once (elementwise: the same numbers as on its angles' copies), then repeated
    x0, y0 = px[ck], py[ck]
    ex, ey = px[ck + 1] - x0, py[ck + 1] - y0
    num = x0 * ey - y0 * ex
    h0 = np.hypot(x0, y0)
    ends = np.maximum(h0, np.hypot(x0 + ex, y0 + ey))
    ex, ey, num, ends, h0 = (np.repeat(a, cnt) for a in (ex, ey, num, ends, h0))
    # the ray at angle g meets the chord where r (cos g, sin g) = P_k + s E
    den = ex * cs[1][gi] - ey * cs[0][gi]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(np.abs(den) > 0.0, num / -den, h0)
    # (a ray almost along a chord: a chord's points are never farther than its ends)
    r = clip(r, 0.0, ends)
    env[gi] = np.maximum(env[gi], r)


def coordinate_range(arrays, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Smallest and largest of each of the first ``k`` coordinates over point arrays ``(..., 3)``.

    One strided reduction per coordinate: some 30 times faster than ``min(axis=0)`` over an
    ``(m, 3)`` view, which numpy runs three elements at a time.
    """
    lo = np.array([min(float(a[..., j].min()) for a in arrays) for j in range(k)])
    hi = np.array([max(float(a[..., j].max()) for a in arrays) for j in range(k)])
    return lo, hi


def _interp_turn(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """``np.interp(x, xp, fp, period=2π)`` for angles ``xp`` already sorted in ``[-π, π]`` and ``x`` in
    ``[-π, π)``: the samples wrapped once at each end, without the sort and reduction ``period`` repeats."""
    return np.interp(x, np.concatenate([xp[-1:] - math.tau, xp, xp[:1] + math.tau]),
                     np.concatenate([fp[-1:], fp, fp[:1]]))


def _composite_gauss(breaks: np.ndarray, n_total: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights over the periodic intervals between ``breaks``.

    The integrand is smooth inside each interval, so the rule converges
    spectrally where the trapezoidal rule would only converge algebraically.
    """
    b = np.sort(np.mod(breaks, math.tau))
    edges = np.concatenate([b, [b[0] + math.tau]])
    k = max(12, int(math.ceil(n_total / len(b))))
    x, w = gauss_legendre(k)
    lo, hi = edges[:-1, None], edges[1:, None]
    nodes = 0.5 * (hi - lo) * (x + 1.0) + lo
    weights = 0.5 * (hi - lo) * w
    return np.mod(nodes.ravel(), math.tau), weights.ravel()


def _split_gauss(t0: float, t1: float, breaks: np.ndarray, n_total: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights over ``[t0, t1]`` split at the (periodic) ``breaks`` inside it.

    A trimmed ``v`` range of a lines-and-arcs outline crosses the outline's joins, where the
    integrand is only C0 or C1: one rule over the whole range converges algebraically (a
    0.03 % volume error on a 3 rad cut-away of the almond at 256 nodes), one per smooth piece
    spectrally.
    """
    b = np.mod(np.asarray(breaks, float), math.tau)
    k0, k1 = math.floor((t0 - math.tau) / math.tau), math.ceil(t1 / math.tau) + 1
    inner = np.unique(np.concatenate([b + math.tau * k for k in range(k0, k1)]))
    span = t1 - t0
    inner = inner[(inner > t0 + 1e-12 * span) & (inner < t1 - 1e-12 * span)]
    edges = np.concatenate([[t0], inner, [t1]])
    k = max(12, int(math.ceil(n_total / (len(edges) - 1))))
    x, w = gauss_legendre(k)
    lo, hi = edges[:-1, None], edges[1:, None]
    return (0.5 * (hi - lo) * (x + 1.0) + lo).ravel(), (0.5 * (hi - lo) * w).ravel()


#: the narrowest range of ``u`` or ``w`` (a fraction) and of ``v`` (rad) a :class:`Trim` keeps: a
#: thinner slice is no solid the CAD layer can make (v = [0, 1e-9] failed late, "0 solids")
TRIM_MIN_WIDTH = 1e-3


@dataclass(frozen=True)
class Trim:
    """Parameter ranges kept of every patch solid.

    Attributes
    ----------
    u : (float, float)
        Range of ``u`` in [0, 1].
    v : (float, float)
        Range of ``v`` in radians; a length of 2π means untrimmed.
    w : (float, float)
        Range of ``w`` in [0, 1]; ``w[0] > 0`` hollows the solid around the spine.
    """

    u: tuple[float, float] = (0.0, 1.0)
    v: tuple[float, float] = (0.0, math.tau)
    w: tuple[float, float] = (0.0, 1.0)

    def __post_init__(self) -> None:
        # a width of exactly the least, as typed, is taken (1.001 - 1.0 is just under 0.001 in binary: a trial)
        least = TRIM_MIN_WIDTH * (1.0 - 1e-9)
        for name, (lo, hi), top in (("u", self.u, 1.0), ("w", self.w, 1.0)):
            check_range(f"trim {name}[0]", lo, 0.0, 1.0)
            check_range(f"trim {name}[1]", hi, 0.0, 1.0)
            if not hi - lo >= least:  # (w = [0, 1e-12] made a solid 1e-11 mm wide)
                raise DesignError(f"trim {name}", (lo, hi), f"must be an increasing pair within [0, 1], at least "
                                  f"{TRIM_MIN_WIDTH:g} apart")
        v0, v1 = (float(x) for x in self.v)
        if not (math.isfinite(v0) and math.isfinite(v1) and least <= v1 - v0 <= math.tau + 1e-12):
            raise DesignError("trim v", self.v, f"must be an increasing pair spanning at most 2π rad and at least "
                              f"{TRIM_MIN_WIDTH:g} rad")
        object.__setattr__(self, "u", tuple(float(x) for x in self.u))
        object.__setattr__(self, "v", (v0, v1))
        object.__setattr__(self, "w", tuple(float(x) for x in self.w))

    @property
    def full_v(self) -> bool:
        return self.v[1] - self.v[0] >= math.tau - 1e-12

    @property
    def whole(self) -> bool:
        """True when nothing is trimmed: the whole solid of every patch (no cut-away, not hollow)."""
        return self.u == (0.0, 1.0) and self.full_v and self.w == (0.0, 1.0)


def solid_map(patch: PDEPatch, u, v, w, du: int = 0, dv: int = 0, dw: int = 0) -> np.ndarray:
    """``X(u, v, w) = A0(u) + w (X(u, v) - A0(u))`` (eq 4.12) and first partials.

    Only one of ``du, dv, dw`` may be 1.  Arrays broadcast; returns ``(..., 3)`` mm.
    """
    u, v, w = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (u, v, w)))
    X = patch.evaluate(u, v, du=du, dv=dv)
    if dv:
        return w[..., None] * X
    A = patch.spine(u, du=du)
    if dw:
        return X - A
    return A + w[..., None] * (X - A)


@dataclass(frozen=True)
class Face:
    """One face of the boundary of a (trimmed) patch solid, as a map of two parameters.

    ``kind`` is ``"w"`` (a surface ``w = const`` over ``(u, v)``), ``"u"``
    (``u = const`` over ``(w, v)``) or ``"v"`` (``v = const`` over ``(u, w)``);
    ``sign`` (+1/-1) orients it outward for a positively oriented patch.
    """

    patch: int
    kind: str
    value: float
    s_range: tuple[float, float]
    t_range: tuple[float, float]
    sign: float
    periodic_t: bool = False

    def evaluate_grid(self, tablet: "Tablet", s, t, der: str = "") -> np.ndarray:
        """The face (or its ``s``/``t`` derivative) on the tensor grid ``s × t``: (len(s), len(t), 3) mm.

        Uses the patches' fast ``evaluate_grid`` (the remainder series is
        evaluated once per ``t``, not once per point).
        """
        p = tablet.patches[self.patch]
        s = np.asarray(s, dtype=float).reshape(-1)
        t = np.asarray(t, dtype=float).reshape(-1)
        if self.kind == "w":  # (u, v) at w = value
            if der == "t":
                return self.value * p.evaluate_grid(s, t, dv=1)
            du = 1 if der == "s" else 0
            A = p.spine(s, du=du)[:, None, :]
            return A + self.value * (p.evaluate_grid(s, t, du=du) - A)
        if self.kind == "u":  # (w, v) at u = value
            X = p.evaluate_grid([self.value], t, dv=1 if der == "t" else 0)[0]  # (nt, 3)
            if der == "t":
                return s[:, None, None] * X[None]
            A = p.spine(np.array([self.value]))[0]
            if der == "s":
                return np.broadcast_to(X - A, (s.size,) + X.shape).copy()
            return A + s[:, None, None] * (X - A)[None]
        # "v": (u, w) at v = value
        du = 1 if der == "s" else 0
        X = p.evaluate_grid(s, [self.value], du=du)[:, 0, :]  # (ns, 3)
        A = p.spine(s, du=du)
        if der == "t":
            Xp = p.evaluate_grid(s, [self.value])[:, 0, :]
            return np.broadcast_to((Xp - p.spine(s))[:, None, :], (s.size, t.size, 3)).copy()
        return A[:, None, :] + t[None, :, None] * (X - A)[:, None, :]

    def evaluate(self, tablet: "Tablet", s, t, der: str = "") -> np.ndarray:
        p = tablet.patches[self.patch]
        s, t = np.broadcast_arrays(np.asarray(s, float), np.asarray(t, float))
        c = np.full(s.shape, self.value)
        if self.kind == "w":  # (s, t) = (u, v)
            args = (s, t, c)
            d = {"": {}, "s": {"du": 1}, "t": {"dv": 1}}[der]
        elif self.kind == "u":  # (s, t) = (w, v)
            args = (c, t, s)
            d = {"": {}, "s": {"dw": 1}, "t": {"dv": 1}}[der]
        else:  # "v": (s, t) = (u, w)
            args = (s, c, t)
            d = {"": {}, "s": {"du": 1}, "t": {"dw": 1}}[der]
        return solid_map(p, *args, **d)


@dataclass(frozen=True)
class Band:
    """The band of a tablet: the patch that is its side wall (the die forms it).

    Attributes
    ----------
    patch : int
        Index of the band patch.
    z0, z1 : float
        Heights (mm) of its bottom and top edges.
    bulge : float
        Largest outward plan distance (mm) of the patch from its end curve (0 when it bows
        inward, or leaves it by rounding only, under 1e-12 of its size): the PDE surface between the two edges may bulge a little (the thesis's
        10 mm shallow convex round: 1.4 µm), which a die bore has to clear.
    inward : float
        Largest inward plan distance (mm) of the patch from its end curve, rounding aside as for
        ``bulge`` (a 15 mm almond's band: 7e-8 mm): how much farther than its edges the band may stand from a
        die bore.
    """

    patch: int
    z0: float
    z1: float
    bulge: float
    inward: float = 0.0

    @property
    def height(self) -> float:
        """The band's height (mm)."""
        return self.z1 - self.z0


@dataclass(frozen=True, eq=False)
class Tablet:
    """A tablet: ordered PDE patches forming a closed surface, plus its solid.

    Parameters
    ----------
    patches : tuple of PDEPatch
        In order along the chain (bottom to top for the thesis's shapes).
    name : str
        Design name (used for file names and the STEP product).
    family : str
        Family the tablet was built from (``"free_form"`` when given patch by patch).
    params : dict
        The family's parameters (mm), for reports; kept read-only (a
        :class:`~tabletcad.readonly.TableDict`).
    trim : Trim
        Parameter ranges kept (default: everything).
    nominal : callable, optional
        Signed distance ``f(points (m, 3)) -> (m,)`` (mm) to the exact shape the
        tablet approximates, for :meth:`nominal_deviation`.
    """

    patches: tuple
    name: str = "tablet"
    family: str = "free_form"
    params: dict = field(default_factory=dict)
    trim: Trim = field(default_factory=Trim)
    nominal: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)
    nominal_name: str = ""
    tol: Tolerances = field(default=DEFAULT, repr=False)

    def __post_init__(self) -> None:
        patches = tuple(self.patches)
        if not patches:
            raise DesignError("patches", 0, "a tablet needs at least one patch")
        for i, p in enumerate(patches):
            if not isinstance(p, PDEPatch):
                raise DesignError(f"patch {i}", type(p).__name__, "must be a PDEPatch")
        object.__setattr__(self, "patches", patches)
        if not isinstance(self.params, TableDict):  # read-only, as the tablet is: its reports read them
            object.__setattr__(self, "params", TableDict(self.params))

    # ------------------------------------------------------------------ topology
    def _end_is_shared(self, i: int, end: int) -> bool:
        """Whether patch ``i``'s u-end (0 or 1) is shared with a neighbour in the chain."""
        j = i - 1 if end == 0 else i + 1
        if not 0 <= j < len(self.patches):
            return False
        xa, xb = self._end_row(i, end), self._end_row(j, 1 - end)
        scale = max(1.0, float(np.abs(xa).max()))
        return float(norm3(xa - xb).max()) <= 1e-9 * scale  # (numpy.linalg.norm's values along the last axis)

    def _edge_v(self) -> np.ndarray:
        """``v`` samples of the topology checks: 64 around, or 4 meridians on a tablet of revolution
        (every meridian of a patch of revolution meets its neighbour and the axis alike)."""
        return linspace(0.0, math.tau, 4 if self.revolution is not None else 64, endpoint=False)

    def _end_row(self, i: int, end: int) -> np.ndarray:
        """Patch ``i``'s boundary curve ``u = end`` at :meth:`_edge_v` (read-only), both ends of a patch
        from one evaluation and kept: the topology checks ask for each end several times."""
        rows = self.__dict__.setdefault("_end_rows", {})
        if i not in rows:
            X = self.patches[i].evaluate_grid(np.array([0.0, 1.0]), self._edge_v())
            X.setflags(write=False)
            rows[i] = X
        return rows[i][end]

    def _end_is_point(self, i: int, end: int) -> bool:
        """Whether patch ``i``'s boundary curve ``u = end`` is one point (to 1e-12 of its size); kept (the
        faces and the seams ask for each end)."""
        points = self.__dict__.setdefault("_end_points", {})
        hit = points.get((i, end))
        if hit is None:
            x = self._end_row(i, end)  # (its extent by coordinate: numpy.ptp's max - min)
            hit = float((x.max(axis=0) - x.min(axis=0)).max()) <= 1e-12 * max(1.0, float(np.abs(x).max()))
            points[(i, end)] = hit
        return hit

    def mirror(self) -> tuple[float, tuple[int, ...]] | None:
        """``(z0, twin)`` when the solid is its own mirror image in the plane ``z = z0`` patch by patch,
        else None.  Patch ``i`` is then patch ``twin[i] = n - 1 - i`` reflected with ``u`` reversed
        (:meth:`PDEPatch.mirrors`; the middle patch of an odd chain, a band, its own twin).

        Only a whole solid (no trim) whose nominal says these very patches were built so
        (``nominal.mirror_z`` and ``nominal.mirror_patches``: a swept family's lower face is its upper
        one reflected; a tablet given other patches with that nominal is not vouched for, since a
        patch's series does not show all of its data curves) and whose patches' series confirm it.  The checks then measure the patches ``i <= twin[i]`` and give
        each twin its patch's figure, reflected (:meth:`measured`).  Cached.
        """
        hit = self.__dict__.get("_mirror", ())
        if hit != ():
            return hit
        z0 = getattr(self.nominal, "mirror_z", None)
        made = getattr(self.nominal, "mirror_patches", ())
        n = len(self.patches)
        out = None
        built = len(made) == n and all(a is b for a, b in zip(made, self.patches))
        if z0 is not None and built and self.trim.whole:
            twin = tuple(n - 1 - i for i in range(n))
            if all(self.patches[i].mirrors(self.patches[j], float(z0)) for i, j in enumerate(twin) if j <= i):
                out = (float(z0), twin)
        object.__setattr__(self, "_mirror", out)
        return out

    def measured(self) -> list[int]:
        """The patches the checks measure: every patch, or of a :meth:`mirror` solid those with
        ``i <= twin[i]`` (the lower half and the middle patch)."""
        m = self.mirror()
        return list(range(len(self.patches))) if m is None else [i for i, j in enumerate(m[1]) if i <= j]

    def faces(self) -> list[Face]:
        """The faces bounding the (trimmed) solid, oriented outward (up to the global sign)."""
        hit = self.__dict__.get("_faces")
        if hit is None:
            hit = tuple(self._make_faces())
            object.__setattr__(self, "_faces", hit)
        return list(hit)

    def _make_faces(self) -> list[Face]:
        t = self.trim
        out: list[Face] = []
        full_u = t.u == (0.0, 1.0)
        for i, _ in enumerate(self.patches):
            out.append(Face(i, "w", t.w[1], t.u, t.v, +1.0, t.full_v))
            if t.w[0] > 0.0:
                out.append(Face(i, "w", t.w[0], t.u, t.v, -1.0, t.full_v))
            for end, uval, sgn in ((0, t.u[0], +1.0), (1, t.u[1], -1.0)):
                # X(u, v, w): the u-face orientation: outward normal ∝ ∓ X_v × X_w
                if full_u and (self._end_is_point(i, end) or self._end_is_shared(i, end)):
                    continue
                out.append(Face(i, "u", uval, t.w, t.v, sgn, t.full_v))
            if not t.full_v:
                out.append(Face(i, "v", t.v[0], t.u, t.w, +1.0, False))
                out.append(Face(i, "v", t.v[1], t.u, t.w, -1.0, False))
        return out

    # ------------------------------------------------------------------ quadrature
    def _rules(self, face: Face, nu: int | None = None, nv: int | None = None):
        nu = nu or self.tol.quad_u
        if nv is None and face.kind in ("w", "u") and self.patches[face.patch].revolution is not None:
            # the integrands do not depend on v: any trapezoidal rule (or Gauss rule, on a cut-away's
            # v range) is exact
            nv = _REVOLUTION_NV
        nv = nv or self.tol.quad_v
        xs, ws = gauss_legendre(nu)
        s0, s1 = face.s_range
        s = 0.5 * (s1 - s0) * (xs + 1.0) + s0
        sw = 0.5 * (s1 - s0) * ws
        t0, t1 = face.t_range
        bps = self.patches[face.patch].breakpoints() if face.kind in ("w", "u") else np.zeros(0)
        if face.periodic_t and bps.size:
            t, tw = _composite_gauss(bps, nv)
        elif face.periodic_t:
            t = t0 + np.arange(nv) * (math.tau / nv)
            tw = np.full(nv, math.tau / nv)
        elif bps.size:  # a trimmed v range: Gauss-Legendre per smooth piece between the outline's joins
            t, tw = _split_gauss(t0, t1, bps, nv if face.kind == "w" else max(nv // 4, 32))
        else:
            xt, wt = gauss_legendre(nv if face.kind == "w" or nv == _REVOLUTION_NV else max(nv // 4, 32))
            t = 0.5 * (t1 - t0) * (xt + 1.0) + t0
            tw = 0.5 * (t1 - t0) * wt
        return s, sw, t, tw

    def _face_integrals(self, face: Face, nu=None, nv=None, solid: list | None = None) -> tuple[float, float, float]:
        """(area, signed volume contribution (1/3)∫X·n dA, plan-area contribution ∫max(n_z,0) dA).

        With ``solid`` (a list), an outer face ``w = 1`` whose rule is :meth:`solid_volume`'s
        (the whole solid at the default rules) also appends its patch's triple integral of the
        solid map's Jacobian, from the same surface samples."""
        s, sw, t, tw = self._rules(face, nu, nv)
        if face.kind == "w":  # the patch's own grids, coordinates first (each one contiguous block)
            X, Xs, Xt = self._w_face_grids(face, s, t)
        else:
            X, Xs, Xt = (np.moveaxis(face.evaluate_grid(self, s, t, der), -1, 0) for der in ("", "s", "t"))
        if solid is not None and face.kind == "w" and face.value == 1.0 and face.sign > 0:
            u, uw, v, vw = self._solid_rules(face.patch)
            if np.array_equal(u, s) and np.array_equal(uw, sw) and np.array_equal(v, t) and np.array_equal(vw, tw):
                # (a level patch's grids are jet_grid's: z from its spine, no z along v)
                level = self.patches[face.patch].level
                solid.append(self._jacobian_integral(face.patch, u, uw, vw, X, Xs, Xt, level=level))
        n = cross_first(Xs, Xt)
        if face.sign < 0:
            n = -n
        # Σ_ij sw_i tw_j f_ij as two products (no weight grid)
        area = float(sw @ np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) @ tw)
        vol = float(sw @ (X[0] * n[0] + X[1] * n[1] + X[2] * n[2]) @ tw) / 3.0
        return area, vol, float(sw @ n[2] @ tw)

    def _w_face_grids(self, face: Face, s: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A face ``w = const`` and its ``s`` (``u``) and ``t`` (``v``) partials on the grid ``s × t``,
        coordinates first: three ``(3, len(s), len(t))`` arrays (mm; mm per unit parameter).  The outer
        surface ``w = 1`` is the patch itself."""
        p = self.patches[face.patch]
        X, Xs, Xt = p.jet_grid(s, t)
        w = face.value
        if w == 1.0:
            return X, Xs, Xt
        A = p.spine(s).T[:, :, None]
        As = p.spine(s, du=1).T[:, :, None]
        return A + w * (X - A), As + w * (Xs - As), w * Xt

    @property
    def orientation(self) -> float:
        """+1 if the patches' ``X_u × X_v`` points out of the solid, -1 if inward (computed once)."""
        hit = self.__dict__.get("_orientation")
        if hit is None:
            vol = sum(self._face_integrals(f, 24, 64)[1] for f in self.faces())
            hit = 1.0 if vol >= 0.0 else -1.0
            object.__setattr__(self, "_orientation", hit)
        return hit

    def properties(self, nu: int | None = None, nv: int | None = None) -> dict[str, Any]:
        """Area and volume by quadrature (eqs 4.8, 4.9), per face and in total.

        Gauss-Legendre in ``u`` (and ``w``) and the trapezoidal rule in periodic
        ``v`` (spectrally accurate for these smooth periodic integrands; four points on a
        patch of revolution, whose integrands do not depend on ``v``).

        Returns
        -------
        dict with ``surface_area_mm2``, ``volume_mm3`` and ``patches`` (per patch: ``surface_area_mm2`` of its outer surface and
        ``volume_mm3``, its term ``(1/3)∫X·n dA`` of the divergence theorem,
        which depends on the origin while the total does not).
        """
        default = nu is None and nv is None
        if default and "_properties" in self.__dict__:
            return copy.deepcopy(self.__dict__["_properties"])
        sgn = None
        per = [dict(surface_area_mm2=0.0, volume_mm3=0.0, other_faces_area_mm2=0.0) for _ in self.patches]
        tot_a = tot_v = 0.0
        rows = []
        # at the default rules on a whole solid, the outer faces' samples also give solid_volume()
        solid = [] if default and self.trim.whole and "_solid_volume" not in self.__dict__ else None
        m = self.mirror()
        done: dict[int, tuple[float, float, float, float | None]] = {}  # a mirror solid's patches' outer faces
        for f in self.faces():
            j = None if m is None or f.kind != "w" or f.value != 1.0 or f.sign < 0 else m[1][f.patch]
            if j is not None and j in done:
                # reflected with u reversed, X' = M X + 2 z0 e_z and n' = M n: the same area and plan,
                # X'·n' = X·n - 2 z0 n_z, and the same Jacobian integral of the solid map
                a, v, pz, jac = done[j]
                rows.append((f, a, v - 2.0 * m[0] * pz / 3.0, -pz))
                if solid is not None and jac is not None:
                    solid.append(jac)
                continue
            k = len(solid) if solid is not None else 0
            a, v, pz = self._face_integrals(f, nu, nv, solid)
            rows.append((f, a, v, pz))
            if j is not None:
                done[f.patch] = (a, v, pz, solid[k] if solid is not None and len(solid) > k else None)
        if solid is not None and len(solid) == len(self.patches):
            object.__setattr__(self, "_solid_volume", float(abs(sum(solid))))
        vol = sum(r[2] for r in rows)
        sgn = 1.0 if vol >= 0 else -1.0
        for f, a, v, pz in rows:
            tot_a += a
            tot_v += sgn * v
            if f.kind == "w" and f.sign > 0:
                per[f.patch]["surface_area_mm2"] += a
            else:
                per[f.patch]["other_faces_area_mm2"] += a
            per[f.patch]["volume_mm3"] += sgn * v
        out = dict(
            surface_area_mm2=tot_a,
            volume_mm3=tot_v,
            orientation=sgn,
            patches=per,
        )
        if default:  # a tablet is immutable: computed once, handed out as copies
            object.__setattr__(self, "_properties", copy.deepcopy(out))
        return out

    def band(self) -> Band | None:
        """The band patch (:class:`Band`), or None when the tablet has none (a sphere, a free form).

        A band patch has plan-identical horizontal end curves at different heights and stays
        within 1 % of that height of its end curve in plan (a side wall, not a dome).
        Cached: a tablet is immutable.
        """
        if "_band" not in self.__dict__:
            object.__setattr__(self, "_band", self._find_band())
        return self.__dict__["_band"]

    def plan_overhang(self) -> float:
        """How far (mm) the tablet's plan reaches beyond its band's edge curve: the band's own bulge, or
        more where a PDE dome overhangs the band (the thesis caplet's top dome by 2 µm), so that a die
        bore grown by it clears the whole tablet.  Exact (polished) for a tablet of revolution and for
        one of scaled copies of one plan ellipse (:attr:`section`: the largest section's reach less the
        band's, an upper bound of the normal distance between the two similar ellipses); the band's
        bulge otherwise (a family's cups lie inside its band).  0 without a band.  Cached."""
        hit = self.__dict__.get("_overhang")
        if hit is None:
            b = self.band()
            hit = 0.0 if b is None else b.bulge
            if b is not None and self.trim.whole:
                edge = self.patches[b.patch]
                if self.revolution is not None:
                    r_band = float(np.hypot(*edge.evaluate(0.0, 0.0)[:2]))
                    hit = max(hit, self._largest_radius() - r_band)
                elif self.section is not None and self._one_plan():
                    r_band = abs(float(edge.section.profile(np.array([0.0]))[0, 0]))
                    reach = float(self.section[0].reach().max())
                    hit = max(hit, (self._radius_range()[1] - r_band) * reach)
            if b is not None:  # rounding is no overhang (the scale: the band's own reach, not a costly bounds())
                meridians = linspace(0.0, math.tau, 16, endpoint=False)
                reach = float(np.abs(self.patches[b.patch].evaluate(0.0, meridians)).max())
                hit = float(hit) if hit > 1e-12 * max(1.0, reach) else 0.0
            object.__setattr__(self, "_overhang", hit)
        return hit

    def _find_band(self) -> Band | None:
        v = linspace(0.0, math.tau, 96, endpoint=False)
        gap = self.tol.seam_gap  # the end curves are the design's own: flat and identical to round-off
        for i, p in enumerate(self.patches):
            x0, x1 = p.evaluate(0.0, v), p.evaluate(1.0, v)
            if float(np.ptp(x0[:, 2])) > gap or float(np.ptp(x1[:, 2])) > gap:
                continue
            if float(np.abs(x1[:, :2] - x0[:, :2]).max()) > gap:
                continue
            z0, z1 = float(x0[0, 2]), float(x1[0, 2])
            if abs(z1 - z0) <= gap:
                continue
            X = p.evaluate_grid(linspace(0.0, 1.0, 65), v)
            dev = X[..., :2] - x0[None, :, :2]
            if float(np.linalg.norm(dev, axis=-1).max()) > 0.01 * abs(z1 - z0):
                continue
            out = x0[:, :2] - x0[:, :2].mean(axis=0)  # outward (star-shaped outlines about their centroid)
            out /= np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-300)
            along = np.einsum("uvc,vc->uv", dev, out)
            bulge, inward = float(along.max()), float(-along.min())
            # rounding is no bulge: a straight band's 1e-16 mm on one machine's BLAS had the die bore
            # offset by MIN_BORE_OFFSET_MM there and not on another
            least = 1e-12 * max(1.0, float(np.abs(x0).max()))
            return Band(i, min(z0, z1), max(z0, z1), bulge if bulge > least else 0.0, inward if inward > least else 0.0)
        return None

    def plan_area(self, nu: int = 33, nv: int = 2048) -> float | None:
        """Area (mm²) of the silhouette seen along z (the tablet's plan).

        The silhouette is taken as star-shaped about the plan centre: along
        every sampled ``v`` line of every patch the point farthest from the
        centre is found (the best of ``nu`` samples, polished by Newton steps
        on ``|X_xy - c|²`` when it lies inside the line), and the outer envelope
        of these points (polar angle, radius) is integrated as ``½∮ r² dφ``, with
        ``r(φ)`` interpolated linearly between the lines' points (an error of order
        ``(2π / nv)²``: 1.6e-7 to 1.2e-6 relative on the shaped samples at 2048) and that
        error removed by one Richardson step against the same envelope from every other
        line (``(4 A_nv - A_nv/2) / 3``, in the same time: within 7e-9 relative of the exact
        area of the caplet's ellipse and of the same estimate from 16384 lines on the shaped
        samples, whose estimates from 8192 and 16384 lines agree to 4e-10).  ~1e-12 relative
        from the polish; 33 samples along a line find the basin of its farthest point (on
        every sample design the area agreed with 129 to 6e-15 relative, in half the time).

        A tablet of revolution (:attr:`revolution`) is the disc of its largest profile radius,
        ``π R_max²``, with ``R_max`` polished to ~1e-12 in ``u``; so is a tablet of scaled copies
        of one centred plan ellipse (:attr:`section`: the thesis's ovals and caplet), whose plan is
        its widest section, of area ``π R_max²`` with ``R`` its equal-area radius.  Trimmed in ``w``
        and ``v`` (radii ``R >= 0``) it is the annular sector ``½ ((w1 R_max)² - (w0 R_min)²) (v1 - v0)``
        (the union of each patch's radii ``w0 R`` to ``w1 R``), which holds a cut-away's cut faces.
        A shaped cut-away (``v`` trimmed, ``w`` from 0) whose spine stays at one plan point is
        the union of fans from that point (:meth:`_plan_area_cut`); one whose spine moves in plan,
        or a hollow shaped cut-away, has no plan area here (``None``).  A hollow whole solid (``w`` from
        ``w0 > 0``) loses the hole seen through it, measured as star-shaped about the plan centre, unless
        some row's inner curve encloses no area (a face closing at a point or a segment, as every family
        tablet's does): then nothing inside the outline is seen through.
        """
        t = self.trim
        if self.section is not None:
            if t.full_v and t.w[0] == 0.0:  # the widest section's area (det S = 1)
                return math.pi * (t.w[1] * self._largest_radius()) ** 2
            # from w = 0 every patch's band of radii starts at the axis: the tablet's range of R suffices
            radii = [self._radius_range()] if t.w[0] == 0.0 else self._section_radii()
            if min(r[0] for r in radii) >= -self.tol.revolution and self._one_plan():  # R >= 0 but for round-off
                # the solid at (u, v) covers the radii w0 R(u) to w1 R(u) along P(v): each patch the band
                # w0 R_min to w1 R_max, and their union the annular sector(s) over v0..v1 (det S = 1)
                bands = sorted((t.w[0] * max(lo, 0.0), t.w[1] * hi) for lo, hi in radii)
                area, (a, b) = 0.0, bands[0]
                for lo, hi in bands[1:] + [(math.inf, math.inf)]:
                    if lo > b:
                        area += b * b - a * a
                        a, b = lo, hi
                    else:
                        b = max(b, hi)
                return 0.5 * area * (t.v[1] - t.v[0])
        if not t.full_v:
            return self._plan_area_cut(nu, nv) if t.w[0] == 0.0 else None
        return self._plan_area_sampled(nu, nv)

    def _plan_area_cut(self, nu: int = 33, nv: int = 2048) -> float | None:
        """:meth:`plan_area` of a cut-away (``v`` trimmed, ``w`` from 0) whose spine ``A0(u)`` stays at one
        plan point ``c`` (to 1e-9 of the tablet's size; else ``None``).

        The solid over a line ``u`` is the fan of segments from ``c`` to its outer curve
        ``X(u, v0..v1)`` (eq 4.12), so the plan is star-shaped about ``c`` and its area is
        ``½ ∫ r(φ)² dφ`` over the angles the fans cover, ``r(φ)`` the largest radius of any fan
        at ``φ``.  The fans taken are those of the ``nu`` lines ``u`` of every patch (``nv``
        points each), of the farthest point along each of the ``nv`` lines ``v`` (polished in
        ``u`` as in :meth:`_plan_area_sampled`) and of the two cut faces (their edges ``X(u, v0)``,
        ``X(u, v1)`` at 1025 ``u`` each), each the triangles from ``c`` over its chords; ``r`` is
        their largest at the midpoints of about 8 ``nv`` steps across the covered angles (or the
        whole turn, where the fans reach round), every fan's end angle the end of a step (the
        envelope jumps there), with one Richardson step against the same from every other line
        ``v`` (the chords' error is of second order).  On the shaped samples' cut-aways (wedges of
        0.05 rad to nearly the whole turn, trims in ``u`` too) the area from ``nv = 8192`` agrees
        to 4e-9 relative, and the union of the solid's projected boundary (scanlines over its
        triangles) converges to it at second order (``tests/test_core_plan_cutaway.py``).
        """
        t = self.trim
        ue = linspace(t.u[0], t.u[1], 1025)
        spine = np.concatenate([p.spine(ue)[:, :2] for p in self.patches])
        c = 0.5 * (spine.min(axis=0) + spine.max(axis=0))
        nv += nv % 2  # nv intervals: every other line keeps both ends (the Richardson step)
        u, v = linspace(t.u[0], t.u[1], nu), linspace(t.v[0], t.v[1], nv + 1)
        pts = [self._outer_grid(p, u, v, axes=(0, 1)) for p in self.patches]
        size = max(float(np.hypot(X[0] - c[0], X[1] - c[1]).max()) for X in pts)
        if np.abs(spine - c).max() > 1e-9 * max(size, 1.0):
            return None
        tiny = 1e-9 * max(size, 1.0)
        lines = []  # (x, y relative to c, index along v or None) of every polyline whose fan is in the plan
        cols = np.arange(nv + 1)
        for p, X in zip(self.patches, pts):
            dx, dy = X[0] - c[0], X[1] - c[1]
            lines += [(dx[k], dy[k], cols) for k in range(nu)]  # each line u's fan
            r2 = dx * dx + dy * dy
            i = np.argmax(r2, axis=0)
            best = r2[i, cols]
            d = np.column_stack([dx[i, cols], dy[i, cols]])
            inner = (i > 0) & (i < nu - 1)
            if inner.any():
                k = np.flatnonzero(inner)
                _, best[k], d[k] = self._farthest_along_u(p, c, u[i[k]], v[k], best[k], u[1] - u[0])
            lines.append((d[:, 0], d[:, 1], cols))
            for ve in t.v:  # the cut faces: fans over their outer edges
                E = self._outer(p, ue, np.full(ue.shape, ve))[:, :2] - c
                lines.append((E[:, 0], E[:, 1], None))
        polar = []
        for x, y, idx in lines:
            keep = np.hypot(x, y) > tiny  # (the poles: no direction)
            polar.append((np.arctan2(y[keep], x[keep]), x[keep], y[keep], None if idx is None else idx[keep]))
        # angles from the middle of the widest direction no point has (the cut's gap), if any
        phi = np.sort(np.concatenate([a for a, *_ in polar]), kind=_ANGLE_SORT)
        gaps = np.diff(np.r_[phi, phi[0] + math.tau])
        j = int(np.argmax(gaps))
        g0 = float(phi[j] + 0.5 * gaps[j])
        covered = gaps[j] <= 8.0 * math.tau / nv  # the fans reach round every direction
        runs = []
        lo, hi = math.inf, -math.inf
        cr, sr = math.cos(g0), math.sin(g0)
        for a, x, y, idx in polar:
            psi = np.mod(a - g0, math.tau)
            x, y = cr * x + sr * y, cr * y - sr * x  # in the frame of the angles psi
            # a line through (or at round-off from) the centre turns by about π there: its fan is the
            # two sides' fans; one across the gap's direction wraps by 2π and is unwrapped
            steps = np.abs(np.diff(psi))
            cuts = (np.flatnonzero(np.abs(steps - math.pi) < 0.5 * math.pi) + 1).tolist()
            for s, e in zip([0, *cuts], [*cuts, psi.size]):
                if e - s >= 2:
                    q = _unwrap(psi[s:e], steps[s:e - 1])
                    runs.append((q, x[s:e], y[s:e], None if idx is None else idx[s:e]))
                    lo, hi = min(lo, float(q.min())), max(hi, float(q.max()))
        if covered:
            lo, hi = 0.0, math.tau
        shifts = (0.0, -math.tau, math.tau) if covered else (0.0,)
        # the monotone pieces of every fan, from all the lines v and from every other one, each as
        # (farthest r², angles, x, y, r²): a piece's r² computed once for its copies shifted by 2π
        sets: list[list[tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]] = []
        for half in (False, True):
            pieces = []
            for q, x, y, idx in runs:
                k = slice(None) if not half or idx is None else idx % 2 == 0
                for qq, xx, yy in _monotone_pieces(q[k], x[k], y[k]):
                    r2 = xx * xx + yy * yy
                    top = float(r2.max())
                    pieces += [(top, qq + sh, xx, yy, r2) for sh in shifts]
            sets.append(pieces)
        # midpoints of 8 nv steps across the range, each piece's ends among the steps' ends: the
        # envelope is continuous within each step (a fan ends at its ends), so the rule is of second order
        ends = np.unique(np.clip([p[1][e] for pieces in sets for p in pieces for e in (0, -1)], lo, hi))
        ends = np.unique(np.r_[lo, ends, hi])
        widths = np.diff(ends)
        n = np.maximum(np.ceil(widths * (8 * nv) / (hi - lo)).astype(int), 1)
        first = np.repeat(ends[:-1], n)
        step = np.repeat(widths / n, n)
        grid = first + (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + 0.5) * step

        cs = (np.cos(grid), np.sin(grid))

        def area(half: bool) -> float:
            env = np.zeros(grid.size)
            pieces = sets[half]
            # the angles each piece spans, all at once; the pieces outside the grid (copies shifted by 2π,
            # most of them) raise nothing and are left out
            s0 = np.searchsorted(grid, [p[1][0] for p in pieces], "left")
            s1 = np.searchsorted(grid, [p[1][-1] for p in pieces], "right")
            inside = np.flatnonzero(s1 > s0)
            # the farthest pieces first (the band's lines): most of the rest then lie inside the envelope
            # and are passed over (the largest of the radii, in any order, is the same number)
            for i in sorted(inside.tolist(), key=lambda i: -pieces[i][0]):
                _, q, x, y, r2 = pieces[i]
                _cover(env, grid, cs, q, x, y, span=(int(s0[i]), int(s1[i])), r2=r2)
            return 0.5 * float(np.sum(env * env * step))

        return (4.0 * area(False) - area(True)) / 3.0

    def _plan_area_sampled(self, nu: int = 33, nv: int = 2048) -> float:
        """:meth:`plan_area` from samples of every patch (any star-shaped plan)."""
        u, v = self._grid(nu, nv)
        # each (2, nu, nv): x and y as contiguous blocks, no stacked copy; a mirror solid's twins
        # have their patches' plans
        patches = [self.patches[i] for i in self.measured()]
        pts = [self._outer_grid(p, u, v, axes=(0, 1)) for p in patches]
        lo, hi = coordinate_range([X.transpose(1, 2, 0) for X in pts], 2)  # views: X[..., j] is the block X[j]
        c = 0.5 * (lo + hi)
        m = 4 * nv
        grid = (np.arange(m) + 0.5) * (math.tau / m) - math.pi
        env_full = np.zeros(m)
        env_half = np.zeros(m)  # from every other v line: the Richardson step below
        cols = np.arange(nv)
        r_max = 0.0
        outer = []
        dx, dy, r2, sq = (np.empty(pts[0].shape[1:]) for _ in range(4))  # (every patch's: no temporaries)
        for X in pts:  # the farthest point along each v line of each patch
            np.subtract(X[0], c[0], out=dx)
            np.subtract(X[1], c[1], out=dy)
            np.multiply(dx, dx, out=r2)  # dx² + dy², as written out
            r2 += np.multiply(dy, dy, out=sq)
            i = np.argmax(r2, axis=0)
            at = i * r2.shape[1] + cols  # each line's farthest sample in the flat blocks (a take)
            rr = np.sqrt(r2.take(at))
            r_max = max(r_max, float(rr.max()))
            d = np.empty((cols.size, 2))
            dx.take(at, out=d[:, 0])
            dy.take(at, out=d[:, 1])
            outer.append((i, rr, d))
        for p, (i, rr, dd) in zip(patches, outer):  # each patch's outer curve r_j(φ), then the envelope
            inner = (i > 0) & (i < nu - 1)
            if inner.any():
                k = np.flatnonzero(inner)
                _, r2, dk = self._farthest_along_u(p, c, u[i[k]], v[k], rr[k] ** 2, u[1] - u[0])
                rr[k], dd[k] = np.sqrt(r2), dk
            keep = rr > 1e-9 * max(r_max, 1.0)
            if np.count_nonzero(keep) < 8:
                continue
            phi = np.arctan2(dd[keep, 1], dd[keep, 0])
            order = np.argsort(phi)
            env_full = np.maximum(env_full, _interp_turn(grid, phi[order], rr[keep][order]))
            half = keep & (cols % 2 == 0)
            if np.count_nonzero(half) >= 8:
                phi = np.arctan2(dd[half, 1], dd[half, 0])
                order = np.argsort(phi)
                env_half = np.maximum(env_half, _interp_turn(grid, phi[order], rr[half][order]))
        hole = 0.0
        if self.trim.w[0] > 0.0:  # hollow solid (a ring): subtract the see-through hole
            A = np.stack([p.spine(linspace(self.trim.u[0], self.trim.u[1], nu)) for p in patches])
            # pts are the outer surface w = w1: the inner one is w0 / w1 of the way from the spine to it
            k = self.trim.w[0] / self.trim.w[1]
            inner = A[:, :, None, :2] + k * (np.stack(pts).transpose(0, 2, 3, 1) - A[:, :, None, :2])
            # the solid over a row u is the band between its inner and outer curves, so nothing is seen through
            # where some row's inner curve encloses no area: a face closing at a point or a segment (every
            # family tablet's centre; a hollow capsule read 126.73 mm² on numpy 1.24, 130.27 on 2.4, from the
            # noise in the angles of its centre segment's points)
            x, y = inner[..., 0], inner[..., 1]
            enclosed = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=2) - np.roll(x, -1, axis=2) * y, axis=2))
            scale = max(1.0, float(np.abs(inner).max()))
            if float(enclosed.min()) > 1e-9 * scale * scale:
                # a ring's hole, star-shaped about c: each v line's nearest inner point, at its own angle
                rad = np.hypot(x - c[0], y - c[1]).reshape(-1, inner.shape[2])
                j = np.argmin(rad, axis=0)
                cols = np.arange(rad.shape[1])
                di = inner.reshape(-1, inner.shape[2], 2)[j, cols] - c
                phi = np.arctan2(di[:, 1], di[:, 0])
                order = np.argsort(phi)
                hole = 0.5 * float(np.sum(_interp_turn(grid, phi[order], rad[j, cols][order]) ** 2)) * (math.tau / m)
        full = 0.5 * float(np.sum(env_full**2)) * (math.tau / m)
        if nv % 2 or not self.trim.full_v or not (env_half > 0.0).all():
            return full - hole
        # the envelope interpolates r(φ) linearly between the v lines' points: an error of order
        # (2π / nv)², which the same envelope from every other line has four times over
        return (4.0 * full - 0.5 * float(np.sum(env_half**2)) * (math.tau / m)) / 3.0 - hole

    def _farthest_along_u(self, p: PDEPatch, c: np.ndarray, u0: np.ndarray, v: np.ndarray, best: np.ndarray, h: float):
        """Newton polish of ``max_u |X_xy(u, v) - c|²`` from the samples ``u0`` (one per ``v``).

        A step is taken only where the function is concave, at most ``h`` (the
        sample spacing) long and only kept when it increases the distance, so
        the result is never worse than the sample.  Returns ``(u, r², X_xy - c)``.
        """
        lo, hi = self.trim.u
        ub, best = u0.copy(), best.copy()

        def jet(uu, vv):  # X - c, X_u, X_uu in the plan at the points (uu, vv) of the outer surface
            return (self._outer(p, uu, vv)[:, :2] - c, self._outer(p, uu, vv, 1)[:, :2],
                    self._outer(p, uu, vv, 2)[:, :2])

        X, Xu, Xuu = jet(ub, v)
        live = np.arange(ub.size)  # points whose last step gained (one that did not would only repeat it)
        for _ in range(6):
            x, xu, xuu = X[live], Xu[live], Xuu[live]
            g1 = 2.0 * einsum("ij,ij->i", x, xu)
            g2 = 2.0 * (einsum("ij,ij->i", xu, xu) + einsum("ij,ij->i", x, xuu))
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(g2 < 0.0, -g1 / g2, 0.0)
            # a step whose predicted gain, g1 s / 2 for the Newton step s, is below rounding of r²
            # is not taken: at a maximum already in the samples (a band symmetric about u = 1/2)
            # the steps of 1e-16 only moved every point into a scattered evaluation for nothing
            step = np.where(0.5 * g1 * step > _POLISH_GAIN * best[live], step, 0.0)
            un = clip(ub[live] + clip(step, -h, h), lo, hi)
            moved = un != ub[live]
            live, un = live[moved], un[moved]
            if not live.size:
                break
            xn, xun, xuun = jet(un, v[live])
            r2 = einsum("ij,ij->i", xn, xn)
            better = r2 > best[live]
            live = live[better]
            if not live.size:
                break
            ub[live], best[live] = un[better], r2[better]
            X[live], Xu[live], Xuu[live] = xn[better], xun[better], xuun[better]
        return ub, best, X

    def volume(self) -> float:
        """Enclosed volume (mm³) by the divergence theorem (eq 4.9)."""
        return self.properties()["volume_mm3"]

    def surface_area(self) -> float:
        """Surface area (mm²) of the solid's boundary (eq 4.8)."""
        return self.properties()["surface_area_mm2"]

    def solid_volume(self, nu: int | None = None, nv: int | None = None, nw: int = 3) -> float:
        """Volume (mm³) as the triple integral of the solid map's Jacobian, an
        independent check of :meth:`volume` (exact in ``w``: the Jacobian is
        quadratic in ``w``).  At the default rules, a whole solid's figure comes from the
        same surface samples as :meth:`properties` (the two integrals are independent, the
        surface they integrate is one)."""
        default = nu is None and nv is None and nw == 3
        hit = self.__dict__.get("_solid_volume") if default else None
        if hit is not None:
            return hit
        total = 0.0
        for i, p in enumerate(self.patches):
            u, uw, v, vw = self._solid_rules(i, nu, nv)
            X = p.evaluate_grid(u, v, components=True)
            Xu = p.evaluate_grid(u, v, du=1, components=True)
            Xv = p.evaluate_grid(u, v, dv=1, components=True)
            total += self._jacobian_integral(i, u, uw, vw, X, Xu, Xv, nw)
        total = abs(total)
        if default:
            object.__setattr__(self, "_solid_volume", total)
        return total

    def _solid_rules(self, i: int, nu: int | None = None, nv: int | None = None):
        """:meth:`solid_volume`'s nodes and weights ``(u, wu, v, wv)`` for patch ``i``: Gauss-Legendre in
        ``u``, the trapezoidal rule in a whole turn of ``v`` (Gauss-Legendre per smooth piece between an
        outline's joins, or over a trimmed range)."""
        t = self.trim
        nu = nu or self.tol.quad_u
        if nv is None and self.section is not None:
            # the Jacobian does not depend on v: any trapezoidal rule is exact.  On a tablet of one plan
            # ellipse (a circle included) the solid map is (w R(u) M e(v), Z(u)), M = [p q], whose
            # Jacobian is -w R² Z' det M
            nv = _REVOLUTION_NV
        nv = nv or self.tol.quad_v
        xu, wu = gauss_legendre(nu)
        u = 0.5 * (t.u[1] - t.u[0]) * (xu + 1) + t.u[0]
        uw = 0.5 * (t.u[1] - t.u[0]) * wu
        bps = self.patches[i].breakpoints()
        if t.full_v and bps.size:
            v, vw = _composite_gauss(bps, nv)
        elif bps.size:
            v, vw = _split_gauss(t.v[0], t.v[1], bps, nv)
        elif t.full_v:
            v = np.arange(nv) * (math.tau / nv) + t.v[0]
            vw = np.full(nv, math.tau / nv)
        else:
            xv, wv = gauss_legendre(nv)
            v = 0.5 * (t.v[1] - t.v[0]) * (xv + 1) + t.v[0]
            vw = 0.5 * (t.v[1] - t.v[0]) * wv
        return u, uw, v, vw

    def _jacobian_integral(self, i: int, u, uw, vw, X, Xu, Xv, nw: int = 3, level: bool = False) -> float:
        """Patch ``i``'s signed triple integral of the solid map's Jacobian ``X_u · (X_v × (X - A0))``
        (eq 4.12) over the trimmed ``w`` by ``nw``-point Gauss-Legendre, from the surface and its first
        partials on the grid ``u × v`` (weights ``uw``, ``vw``), coordinates first ``(3, len(u), len(v))``.

        At ``w`` the map's partials are ``A0_u + w (X_u - A0_u)``, ``w X_v`` and ``X - A0``, so the
        Jacobian is ``w J1 + w² J2`` with ``J1 = A0_u · C``, ``J2 = (X_u - A0_u) · C``,
        ``C = X_v × (X - A0)``: two surface integrals, weighted by the rule's ``Σ w`` and ``Σ w²``.

        ``level``: the grids are a :attr:`~tabletcad.geometry.patch.PDEPatch.level` patch's from its
        ``jet_grid`` (``X_z`` and ``X_u,z`` its spine's, ``X_v,z = 0``): then ``X - A0`` and ``X_u - A0_u``
        have no ``z``, ``C`` is ``(0, 0, C_z)``, ``J1 = A0_u,z C_z`` and ``J2 = 0``, and only ``C_z`` is
        formed (the terms left out are signed zeros: a non-zero integral is the same number, bit for bit,
        and a zero one at most of the other sign, which the solid's ``abs`` of the patches' sum removes;
        a sample that is not finite is left to the whole sum, whose zero terms it makes NaN)."""
        t = self.trim
        p = self.patches[i]
        xw, ww = gauss_legendre(nw)
        w = 0.5 * (t.w[1] - t.w[0]) * (xw + 1) + t.w[0]
        wwt = 0.5 * (t.w[1] - t.w[0]) * ww
        A = p.spine(u).T[:, :, None]
        Au = p.spine(u, du=1).T[:, :, None]
        if level:
            Cz = Xv[0] * (X[1] - A[1]) - Xv[1] * (X[0] - A[0])
            out = float(np.dot(wwt, w)) * float(uw @ (Au[2] * Cz) @ vw)  # (J2's integral is zero)
            # (a non-finite sample makes the zero terms NaN: then the whole sum below, as it would)
            if math.isfinite(out) and math.isfinite(float(np.sum(Xu[0])) + float(np.sum(Xu[1]))):
                return out
        C = cross_first(Xv, X - A)
        Du = Xu - Au
        J1 = Au[0] * C[0] + Au[1] * C[1] + Au[2] * C[2]
        J2 = Du[0] * C[0] + Du[1] * C[1] + Du[2] * C[2]
        return float(np.dot(wwt, w)) * float(uw @ J1 @ vw) + float(np.dot(wwt, w * w)) * float(uw @ J2 @ vw)

    # ------------------------------------------------------------------ geometry summaries
    def sample(self, nu: int = 65, nv: int = 128) -> np.ndarray:
        """Surface points of every patch on the grid of :meth:`_grid`, shape (patches, nu, nv, 3)."""
        u, v = self._grid(nu, nv)
        return np.stack([p.evaluate_grid(u, v) for p in self.patches])

    def _grid(self, nu: int, nv: int) -> tuple[np.ndarray, np.ndarray]:
        """``nu`` equally spaced ``u`` and ``nv`` ``v`` over the trimmed ranges (``v`` periodic when untrimmed)."""
        t = self.trim
        return linspace(t.u[0], t.u[1], nu), linspace(t.v[0], t.v[1], nv, endpoint=not t.full_v)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box (mm) of the surface (the outer one, ``w = w1``, when ``[trim] w``
        ends before 1), refined to ~1e-9 mm.

        Each extreme is taken from a 97 × 256 sample of every patch and then
        polished by zooming: a 33 × 33 grid around the best point, each round eight
        times finer (the next round's grid still spans two of this one's steps each
        side), until the grid step is below ~6e-8 in ``u`` and ``v``, or, once the grid spans
        1e-3 each side and its best point is a peak inside it, one Newton step from the grid's
        central differences (:meth:`_newton_finish`): on the samples, whole and cut away, the
        extents equal those of a zoom carried on to a step of 6e-12 within 1.7e-14 mm.
        A tablet of revolution untrimmed in ``v`` takes its extents from its profile
        (:attr:`revolution`), polished the same way in ``u`` alone; so does a tablet of one
        plan ellipse (:attr:`section`: ``± R_max √S_xx`` in x, ``± R_max √S_yy`` in y) and a
        trimmed one of either (:meth:`_section_bounds`).
        Cached: a tablet is immutable.
        """
        hit = self.__dict__.get("_bounds")
        if hit is None:
            hit = self._bounds()
            object.__setattr__(self, "_bounds", hit)
        return hit[0].copy(), hit[1].copy()

    @property
    def revolution(self) -> tuple | None:
        """Every patch's :class:`~tabletcad.geometry.revolution.Revolution` when all of them are
        surfaces of revolution about the z axis, else None."""
        revs = tuple(p.revolution for p in self.patches)
        return None if any(r is None for r in revs) else revs

    @property
    def section(self) -> tuple | None:
        """Every patch's :class:`~tabletcad.geometry.revolution.Section` when all of them are
        scaled copies of one centred plan ellipse (the same shape ``S`` to 1e-12), else None.
        A tablet of revolution has one (``S = I``)."""
        hit = self.__dict__.get("_sections", False)
        if hit is False:
            secs = tuple(p.section for p in self.patches)
            hit = None if any(x is None for x in secs) else secs
            if hit is not None:
                S = hit[0].shape
                if any(np.abs(x.shape - S).max() > 1e-12 * max(1.0, float(np.abs(S).max())) for x in hit[1:]):
                    hit = None
            object.__setattr__(self, "_sections", hit)
        return hit

    def _profile_extents(self) -> tuple[float, float, float]:
        """``(R_max, Z_min, Z_max)`` (mm) of the profiles of a tablet of revolution (or of one plan
        ellipse, :attr:`section`, ``R`` its sections' equal-area radius) over the trimmed ``u``
        range (cached), sampled and polished as :meth:`_maxima_over` says."""
        hit = self.__dict__.get("_extents")
        if hit is None:
            out = self._profile_maxima((lambda P: np.abs(P[..., 0]), lambda P: -P[..., 1], lambda P: P[..., 1]))
            hit = (out[0], -out[1], out[2])
            object.__setattr__(self, "_extents", hit)
        return hit

    def _radius_range(self) -> tuple[float, float]:
        """``(R_min, R_max)`` (mm, signed) over every profile of a :attr:`section` tablet and the trimmed
        ``u`` range, polished as :meth:`_profile_extents` (cached)."""
        hit = self.__dict__.get("_rrange")
        if hit is None:
            out = self._profile_maxima((lambda P: P[..., 0], lambda P: -P[..., 0]))
            hit = (-out[1], out[0])
            object.__setattr__(self, "_rrange", hit)
        return hit

    def _profile_maxima(self, quantities) -> list[float]:
        """The largest value of each ``g(profile)`` over every profile (:meth:`_profile_extents`)."""
        return self._maxima_over([r.profile for r in self.revolution or self.section], quantities)

    def _maxima_over(self, curves, quantities) -> list[float]:
        """The largest value of each ``g(c(u))`` over every curve ``c`` of ``u`` and the trimmed ``u`` range.

        Every curve is sampled once (513 points); a quantity is then polished
        (:func:`~tabletcad.geometry.revolution.profile_extreme`) on each curve whose best sample comes within
        ``max |Δ²g|`` (the samples' largest second difference, a bound on what lies between samples) of the
        best sample of all, so no curve that could hold the extreme is skipped."""
        lo, hi = self.trim.u
        u = linspace(lo, hi, 513)
        values = [c(u) for c in curves]
        out = []
        for g in quantities:
            samples = [g(P) for P in values]
            best = max(float(x.max()) for x in samples)
            slack = max(float(np.abs(np.diff(x, 2)).max()) for x in samples)
            out.append(max(profile_extreme(lambda uu, c=c, g=g: g(c(uu)), lo, hi)[1]
                           for c, x in zip(curves, samples) if float(x.max()) >= best - slack))
        return out

    def _one_plan(self) -> bool:
        """Whether every patch of a :attr:`section` tablet has the same plan vectors ``p, q`` (to 1e-12)."""
        plan = self.section[0].plan
        return all(np.abs(x.plan - plan).max() <= 1e-12 for x in self.section)

    def _section_radii(self) -> list[tuple[float, float]]:
        """``(R_min, R_max)`` (mm, signed) of each patch's :attr:`section` profile over the trimmed ``u``
        range, polished (:func:`~tabletcad.geometry.revolution.profile_extreme`; cached)."""
        hit = self.__dict__.get("_radii")
        if hit is None:
            lo, hi = self.trim.u
            hit = [(-profile_extreme(lambda uu, x=x: -x.profile(uu)[..., 0], lo, hi)[1],
                    profile_extreme(lambda uu, x=x: x.profile(uu)[..., 0], lo, hi)[1]) for x in self.section]
            object.__setattr__(self, "_radii", hit)
        return hit

    def _section_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`bounds` of a :attr:`section` tablet, any trim, from its profiles.

        The solid's point at ``(u, v, w)`` is ``(w R(u) P(v), Z(u))``, ``P(v) = p cos v + q sin v``
        (eq 4.12 with the spine on the z axis): each plan coordinate is a product of a factor in
        ``w``, one in ``u`` and one in ``v``, so its extremes lie at the corners of their ranges
        (:meth:`~tabletcad.geometry.revolution.Section.span` in ``v``, the polished profile in ``u``).
        """
        t = self.trim
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        # each coordinate is linear in R for fixed w and v: with one plan for all patches the corners of
        # the tablet's whole range of R give the same extremes as each patch's own
        ranges = [(self.section[0], self._radius_range())] if self._one_plan() else zip(self.section, self._section_radii())
        for sec, (rmin, rmax) in ranges:
            plo, phi = sec.span(*t.v)
            for i in range(2):
                vals = [w * r * c for w in t.w for r in (rmin, rmax) for c in (plo[i], phi[i])]
                lo[i], hi[i] = min(lo[i], min(vals)), max(hi[i], max(vals))
        _, lo[2], hi[2] = self._profile_extents()
        return lo, hi

    def _largest_radius(self) -> float:
        """Largest distance (mm) of a tablet of revolution's surface from the z axis (the largest
        equal-area radius of a :attr:`section`)."""
        return self._profile_extents()[0]

    def _outer(self, p: PDEPatch, u, v, du: int = 0) -> np.ndarray:
        """The solid's outer surface at points ``(u, v)`` (or its ``u`` derivative): the patch's
        surface, or ``A0(u) + w1 (X(u, v) - A0(u))`` when ``[trim] w`` ends at ``w1 < 1`` (eq 4.12)."""
        X = p.evaluate(u, v, du=du)
        w1 = self.trim.w[1]
        if w1 == 1.0:
            return X
        A = p.spine(np.asarray(u, float), du=du)
        return A + w1 * (X - A)

    def _outer_grid(self, p: PDEPatch, u, v, axes: tuple[int, ...] | None = None,
                    out: np.ndarray | None = None) -> np.ndarray:
        """:meth:`_outer` on the grid ``u × v``: (len(u), len(v), 3), or with ``axes`` the coordinates
        ``axes`` as contiguous blocks ``(len(axes), len(u), len(v))`` (``evaluate_grid``'s layout), written
        into ``out`` (mm; C-contiguous, that shape) when given."""
        w1 = self.trim.w[1]
        if axes is None:
            X = p.evaluate_grid(u, v)
            if w1 == 1.0:
                return X
            A = p.spine(np.asarray(u, float))[:, None, :]
            return A + w1 * (X - A)
        X = p.evaluate_grid(u, v, components=True, axes=axes, out=out)
        if w1 == 1.0:
            return X
        A = p.spine(np.asarray(u, float))[:, list(axes)].T[:, :, None]
        return A + w1 * (X - A) if out is None else np.add(A, w1 * (X - A), out=out)

    def _bounds(self) -> tuple[np.ndarray, np.ndarray]:
        t = self.trim
        if self.section is not None and t.full_v:  # ± w1 R_max √S_xx (the largest |R| alone: none missed)
            rmax, zbot, ztop = self._profile_extents()
            rx, ry = t.w[1] * rmax * (np.ones(2) if self.revolution is not None else self.section[0].reach())
            return np.array([-rx, -ry, zbot]), np.array([rx, ry, ztop])
        if self.section is not None:
            return self._section_bounds()
        return self._bounds_sampled()

    def _bounds_sampled(self) -> tuple[np.ndarray, np.ndarray]:
        u, v = self._grid(97, 256)
        # (patches, 3, nu, nv): each coordinate a contiguous block (evaluate_grid's own layout, no transposed
        # copy); a mirror solid's twins reach the same x and y, and z reflected (below)
        patches = [self.patches[i] for i in self.measured()]
        level = all(p.level for p in self.patches)  # then z is each patch's spine's (below): x and y alone
        axes = (0, 1) if level else (0, 1, 2)
        pts = np.empty((len(patches), len(axes), u.size, v.size))
        for k, p in enumerate(patches):  # each patch's grid written in its block (no stacked copy)
            self._outer_grid(p, u, v, axes=axes, out=pts[k])
        lo, hi = pts.min(axis=(0, 2, 3)), pts.max(axis=(0, 2, 3))
        if level:  # the samples' z: their lines' spine heights
            z = np.concatenate([p.spine(u)[:, 2] for p in patches])
            lo, hi = np.append(lo, z.min()), np.append(hi, z.max())
        t = self.trim
        if not t.full_v or t.u != (0.0, 1.0):
            # a cut-away's cut faces run in to the spine A0(u) (eq 4.12), or to w0 of the way out to the
            # surface: their inner edges, on the cut lines v = v0, v1 and u = u0, u1
            line = linspace(t.u[0], t.u[1], 1025)
            inner = [p.spine(line) for p in self.patches]
            if t.w[0] > 0.0:
                ring = linspace(t.v[0], t.v[1], 1025)
                inner = [A + t.w[0] * (p.evaluate(line, np.full(line.shape, vc)) - A)
                         for p, A in zip(self.patches, inner) for vc in t.v]
                inner += [p.spine(np.full(ring.shape, uc)) + t.w[0] * (p.evaluate(np.full(ring.shape, uc), ring)
                                                                       - p.spine(np.full(ring.shape, uc)))
                          for p in self.patches for uc in t.u]
            inner = np.concatenate(inner)
            lo, hi = np.minimum(lo, inner.min(axis=0)), np.maximum(hi, inner.max(axis=0))
        if level:  # z is each patch's spine's alone (PDEPatch.level): its extremes from the spines, polished in u
            zlo, zhi = self._spine_z_range()
            lo[2], hi[2] = min(lo[2], zlo), max(hi[2], zhi)
        for axis in range(2 if level else 3):
            for sign, store in ((-1.0, lo), (1.0, hi)):
                c = pts[:, axis]
                k = int(np.argmax(c) if sign > 0 else np.argmin(c))
                pi, ui, vi = np.unravel_index(k, c.shape)
                val = self._polish_extreme(patches[pi], axis, sign, u[ui], v[vi], u[1] - u[0], v[1] - v[0],
                                           start=float(c[pi, ui, vi]))
                store[axis] = max(store[axis], val) if sign > 0 else min(store[axis], val)
        m = self.mirror()
        if m is not None:  # the twins' z range: the measured patches' reflected in z = z0
            lo[2], hi[2] = min(lo[2], 2.0 * m[0] - hi[2]), max(hi[2], 2.0 * m[0] - lo[2])
        return lo, hi

    def _spine_z_range(self) -> tuple[float, float]:
        """Lowest and highest z (mm) of the patches' spines over the trimmed ``u`` range (:meth:`_maxima_over`):
        the tablet's z extent when every patch is :attr:`~tabletcad.geometry.patch.PDEPatch.level` (the trim's
        ``w`` scales the plan only, eq 4.12)."""
        low, high = self._maxima_over([p.spine for p in self.patches], (lambda A: -A[..., 2], lambda A: A[..., 2]))
        return -low, high

    def _polish_extreme(self, p, axis: int, sign: float, u0: float, v0: float, hu: float, hv: float,
                        start: float | None = None) -> float:
        """Largest ``sign·X[axis]`` near ``(u0, v0)`` (see :meth:`bounds`); ``start``: ``X[axis]`` there, when the
        caller has it (its sample), else evaluated.

        Two passes of: a dense line over the whole ``u`` range at ``v0`` (the
        extreme of a band is nearly flat along ``u``, so its best ``u`` may lie
        far from the sample's), then grids zooming eight times per round; the
        second pass only when its line beats the first zoom's point.
        """
        t = self.trim
        best = sign * (float(self._outer(p, u0, v0)[axis]) if start is None else start)
        n = 33
        for round_ in range(2):
            line = linspace(t.u[0], t.u[1], 513)
            g = sign * self._outer_grid(p, line, np.array([v0]), axes=(axis,))[0, :, 0]
            i = int(np.argmax(g))
            if g[i] > best or (round_ == 0 and g[i] == best):
                best, u0 = float(g[i]), float(line[i])
            elif round_:  # the second line found nothing better: the first zoom's point stands
                break
            a, b = max(hu, line[1] - line[0]), hv
            while a > _ZOOM_STOP or b > _ZOOM_STOP:
                uu = clip(u0 + linspace(-a, a, n), t.u[0], t.u[1])
                vv = v0 + linspace(-b, b, n)
                if not t.full_v:
                    vv = clip(vv, t.v[0], t.v[1])
                g = sign * self._outer_grid(p, uu, vv, axes=(axis,))[0]
                i, j = np.unravel_index(int(np.argmax(g)), g.shape)
                if g[i, j] >= best:
                    best, u0, v0 = float(g[i, j]), float(uu[i]), float(vv[j])
                    if a <= _NEWTON_FINISH and b <= _NEWTON_FINISH:
                        finish = self._newton_finish(p, axis, sign, g, uu, vv, i, j)
                        if finish is not None:  # the grid's peak is a maximum inside it: one step to its top
                            best = max(best, finish)
                            break
                a, b = a / 8.0, b / 8.0
        return sign * best

    def _newton_finish(self, p, axis: int, sign: float, g: np.ndarray, uu: np.ndarray, vv: np.ndarray,
                       i: int, j: int) -> float | None:
        """The value of ``sign·X[axis]`` one Newton step from the grid point ``(uu[i], vv[j])``, its largest
        sample, with the gradient and Hessian from the grid's central differences; None when the point
        has no neighbour in ``v`` or the Hessian is not negative definite (then the zoom goes on), but for a
        grid flat along ``u`` to rounding (a band whose side stands vertical) and a peak on an end of the
        trimmed ``u`` range (a land's rim), whose step is in ``v`` alone.  The step ends a zoom whose spacing is
        at most ``_NEWTON_FINISH / 16`` in place of its last two rounds: on the samples, whole and trimmed, the
        extents equal those of a zoom carried on to a step of 6e-12 within 1.7e-14 mm (the zoom alone, to a
        step of 6e-8: within 1.8e-13)."""
        t = self.trim
        if not 0 < j < g.shape[1] - 1:
            return None
        dv = vv[j + 1] - vv[j]
        if not (dv > 0.0 and abs(vv[j] - vv[j - 1] - dv) <= 1e-9 * dv):  # a grid clipped at an end of the trim
            return None
        gv = (g[i, j + 1] - g[i, j - 1]) / (2.0 * dv)
        hvv = (g[i, j + 1] - 2.0 * g[i, j] + g[i, j - 1]) / (dv * dv)
        du = uu[min(i + 1, g.shape[0] - 1)] - uu[i]
        inside = 0 < i < g.shape[0] - 1 and du > 0.0 and abs(uu[i] - uu[i - 1] - du) <= 1e-9 * du
        noise = 64.0 * np.finfo(float).eps * max(abs(float(g[i, j])), 1.0)  # rounding of the samples (mm)
        if inside:
            gu = (g[i + 1, j] - g[i - 1, j]) / (2.0 * du)
            huu = (g[i + 1, j] - 2.0 * g[i, j] + g[i - 1, j]) / (du * du)
            huv = (g[i + 1, j + 1] - g[i + 1, j - 1] - g[i - 1, j + 1] + g[i - 1, j - 1]) / (4.0 * du * dv)
            det = huu * hvv - huv * huv
            if max(abs(gu) * du, abs(huu) * du * du, abs(huv) * du * dv) <= noise and hvv < 0.0:
                su, sv = 0.0, -gv / hvv  # flat along u to rounding (a band's side): the top of the parabola in v
            elif huu < 0.0 and det > 0.0:
                su = -(hvv * gu - huv * gv) / det
                sv = -(huu * gv - huv * gu) / det
            else:
                return None
        elif uu[i] in t.u and hvv < 0.0:  # the peak on the trim's end u = u0 or u1 (a land's rim): along it in v
            su, sv, du = 0.0, -gv / hvv, math.inf
        else:
            return None
        if abs(su) > du or abs(sv) > dv:  # beyond its neighbours: not the quadratic's top
            return None
        un = float(clip(uu[i] + su, t.u[0], t.u[1]))
        vn = float(vv[j] + sv) if t.full_v else float(clip(vv[j] + sv, t.v[0], t.v[1]))
        return sign * float(self._outer(p, un, vn)[axis])

    def dimensions(self) -> dict[str, float]:
        """``length_mm`` (x extent), ``width_mm`` (y extent), ``height_mm`` (z extent)."""
        lo, hi = self.bounds()
        ext = hi - lo
        return dict(length_mm=float(ext[0]), width_mm=float(ext[1]), height_mm=float(ext[2]))

    def seam_v(self, nv: int = 720) -> np.ndarray:
        """The seam checks' ``v`` samples (rad, sorted): ``nv`` meridians (4 on a tablet of revolution,
        whose meridians are all alike) and each side (1e-7 rad) of every join of the patches' outlines
        (:meth:`PDEPatch.breakpoints`), where a seam's normals turn fastest.  One array for every seam
        check of a tablet (:meth:`seams`, the families' design report), so its patches evaluate the
        data curves there once."""
        cache = self.__dict__.setdefault("_seam_vs", {})
        if nv in cache:
            return cache[nv]
        v = linspace(0.0, math.tau, 4 if self.revolution is not None else nv, endpoint=False)
        joins = [p.breakpoints() for p in self.patches]
        b = np.unique(np.concatenate(joins)) if joins else np.zeros(0)
        if b.size:
            v = np.unique(np.concatenate([v, np.mod(b + 1e-7, math.tau), np.mod(b - 1e-7, math.tau)]))
        v.setflags(write=False)
        cache[nv] = v
        return v

    def seam_rows(self, nv: int = 720) -> tuple[np.ndarray, ...]:
        """Every patch's boundary curves ``u = 0, 1`` and their partials on :meth:`seam_v`: one
        ``(3, 2, len(v), 3)`` array per patch (``X``, ``X_u``, ``X_v`` by end), read-only, three
        evaluations per patch for every seam check of the tablet (:meth:`seams`, the families'
        design report).  Cached."""
        cache = self.__dict__.setdefault("_seam_rows", {})
        if nv not in cache:
            v, ends = self.seam_v(nv), np.array([0.0, 1.0])
            m = self.mirror()
            rows: dict[int, np.ndarray] = {}
            for i in self.measured():
                p = self.patches[i]
                rows[i] = np.stack([p.evaluate_grid(ends, v), p.evaluate_grid(ends, v, du=1), p.evaluate_grid(ends, v, dv=1)])
            if m is not None:  # a twin's ends are its patch's other ends reflected: X' = M X + 2 z0 e_z, X'_u = -M X_u
                flip = np.array([1.0, 1.0, -1.0])
                sign = np.array([1.0, -1.0, 1.0])[:, None, None, None]
                for i, j in enumerate(m[1]):
                    if i > j:
                        R = rows[j][:, ::-1] * flip * sign
                        R[0, ..., 2] += 2.0 * m[0]
                        rows[i] = R
            for R in rows.values():
                R.setflags(write=False)
            cache[nv] = tuple(rows[i] for i in range(len(self.patches)))
        return cache[nv]

    def seams(self, nv: int = 720) -> list[dict[str, Any]]:
        """For every curve shared by consecutive patches: largest gap (mm) and
        largest angle (deg) between the two patches' normals (on :meth:`seam_v`: ``nv`` meridians,
        4 on a tablet of revolution, and each side of the outline's joins)."""
        out = []
        v = self.seam_v(nv)
        rows = self.seam_rows(nv)
        for i in range(len(self.patches) - 1):
            a, b = self.patches[i], self.patches[i + 1]
            (xa, xua, xva), (xb, xub, xvb) = rows[i][:, 1], rows[i + 1][:, 0]
            gap = float(norm3(xa - xb).max())  # (numpy.linalg.norm's values along the last axis)
            if self._end_is_point(i, 1):
                ang = float("nan")
            else:
                # skip points where the shared curve has (nearly) zero speed, such as a
                # corner collapsed to a point: the normals are undefined there
                speed = norm3(xva)
                ok = speed > 1e-6 * float(speed.max())
                na = a.normal(1.0, v[ok], xu=xua[ok], xv=xva[ok])
                nb = b.normal(0.0, v[ok], xu=xub[ok], xv=xvb[ok])
                cosang = clip(einsum("ij,ij->i", na, nb), -1.0, 1.0)
                ang = float(np.degrees(np.arccos(cosang).max()))
            out.append(
                dict(
                    patches=[i, i + 1],
                    max_gap_mm=gap,
                    max_angle_deg=ang,
                    g1=bool(ang == ang and ang <= self.tol.seam_angle_deg),
                )
            )
        return out

    def nominal_deviation(self, nu: int | None = None, nv: int = 256) -> float | None:
        """Largest distance (mm) of the surface from the nominal shape, or None: the largest of
        :meth:`nominal_peaks`."""
        per = self.nominal_peaks(nu, nv)
        return None if per is None else float(per.max())

    def nominal_nu(self) -> int:
        """The default ``nu`` of :meth:`nominal_peaks`: the nominal's own ``deviation_nu`` (a family's
        65: its PDE surface lies within nanometres of the nominal, and on the family samples and 18
        random capsules, rounded triangles and almonds that figure is within 2e-5 relative, 3e-9 µm,
        of the same from ``257 × 512``), else 129 (the thesis's ring tablet lies 3 µm off its nominal
        and its peak needs the finer grid: 4e-6 µm lower from 65)."""
        return int(getattr(self.nominal, "deviation_nu", 129))

    def nominal_grid(self, nu: int | None = None, nv: int = 256) -> tuple[np.ndarray, np.ndarray, float]:
        """The samples ``(u, v, hv)`` of :meth:`nominal_peaks` on a tablet not of revolution: a grid
        half as fine as ``nu × nv`` in each direction (``(nu - 1) // 2 + 1`` values of ``u`` over the
        trimmed range, ends included, and ``nv // 2`` of ``v``), ``hv`` the step in ``v``.  Untrimmed in
        ``v``, a nominal that names its own samples (``nominal.v_samples(n)``: a family's, with each side
        of its outline's joins, where the surface is only piecewise smooth) gives ``v``.  ``nu`` None:
        :meth:`nominal_nu`."""
        nu = self.nominal_nu() if nu is None else nu
        nu_c, nv_c = max((nu - 1) // 2 + 1, 3), max(nv // 2, 4)
        u, v = self._grid(nu_c, nv_c)
        hv = (self.trim.v[1] - self.trim.v[0]) / (nv_c if self.trim.full_v else max(nv_c - 1, 1))
        sampler = getattr(self.nominal, "v_samples", None)
        if sampler is not None and self.trim.full_v:
            v = np.asarray(sampler(nv_c), dtype=float)
        return u, v, hv

    def nominal_peaks(self, nu: int | None = None, nv: int = 256) -> np.ndarray | None:
        """Largest distance (mm) of each patch from the nominal shape (a copy), or None without one.

        Every patch is sampled on :meth:`nominal_grid`; the distance is then polished around the
        largest local maxima of those samples (:meth:`deviation_peaks`), which resolves each peak
        more finely than the whole ``nu × nv`` grid would, at a quarter of its cost; ``nu`` None:
        :meth:`nominal_nu`.  A surface of revolution measured against a nominal of revolution
        (``nominal.axisymmetric``) takes 129 samples of one meridian (``nu`` when given), polished in
        ``u`` (:meth:`meridian_peaks`), since every meridian (in its trimmed ``v`` range) gives the
        same distances.  Cached on the nominal with the patches it
        measured, so a family's certificate (:func:`~tabletcad.families.sweep.certify`, the same
        measurement) and the geometry report share one.
        """
        if self.nominal is None:
            return None
        if self.revolution is not None and getattr(self.nominal, "axisymmetric", False):
            return self.meridian_peaks(129 if nu is None else nu)
        nu = self.nominal_nu() if nu is None else nu
        memo = getattr(self.nominal, "__dict__", self.__dict__).setdefault("_tabletcad_nominal_peaks", {})
        key = (self.trim.u, self.trim.v, nu, nv)
        hit = memo.get(key)
        if hit is not None and len(hit[0]) == len(self.patches) and all(a is b for a, b in zip(hit[0], self.patches)):
            return hit[1].copy()
        u, v, hv = self.nominal_grid(nu, nv)
        per = self.deviation_peaks(u, v, hv)
        per.setflags(write=False)
        if len(memo) >= 8:
            memo.pop(next(iter(memo)))
        memo[key] = (self.patches, per)
        return per.copy()

    def meridian_peaks(self, nu: int = 129) -> np.ndarray:
        """Largest ``|nominal|`` (mm) on each patch of a tablet and nominal of revolution (cached).

        Every meridian gives the same distances (a cut-away's too), so one is sampled at ``nu``
        values of ``u`` per patch, and every local maximum within ``max |Δ²g|`` of the best sample
        (a bound on what lies between samples) and each patch's largest sample are polished in ``u``:
        65 points over one sample step each side, 32 times finer each of two rounds, to a step of
        ``1 / (1024 (nu - 1))`` in ``u`` (all peaks of a round in one evaluation per patch and one
        distance call).  The result is at least each patch's largest sample.
        """
        # kept on the nominal with the patches it measured: a renamed copy of the tablet (the same
        # patches and nominal, as a design file's name makes) and its certificate share it
        memo = getattr(self.nominal, "__dict__", self.__dict__).setdefault("_tabletcad_meridian_peaks", {})
        key = (self.trim.u, nu)
        hit = memo.get(key)
        if hit is not None and len(hit[0]) == len(self.patches) and all(a is b for a, b in zip(hit[0], self.patches)):
            return hit[1].copy()
        lo, hi = self.trim.u
        u = linspace(lo, hi, nu)
        v0 = self.trim.v[0]
        n = len(self.patches)
        pts = np.concatenate([p.evaluate(u, np.full(nu, v0)) for p in self.patches])
        D = self._nominal_distance(pts).reshape(n, nu)
        per = D.max(axis=1)
        slack = float(np.abs(np.diff(D, 2, axis=1)).max()) if nu > 2 else math.inf
        E = np.pad(D, ((0, 0), (1, 1)), mode="edge")
        cand = (D >= E[:, :-2]) & (D >= E[:, 2:]) & (D >= float(per.max()) - slack)
        cand[np.arange(n), np.argmax(D, axis=1)] = True  # and each patch's best: its own figure polished
        js, cs = np.nonzero(cand)
        cu, h, m = u[cs], u[1] - u[0], 65
        for _ in range(2):
            grid = clip(cu[:, None] + linspace(-h, h, m), lo, hi)  # (candidates, m)
            pts = np.empty((len(js), m, 3))
            for j in np.unique(js):
                k = js == j
                pts[k] = self.patches[j].evaluate(grid[k].ravel(), np.full(m * int(k.sum()), v0)).reshape(-1, m, 3)
            vals = self._nominal_distance(pts.reshape(-1, 3)).reshape(len(js), m)
            best = np.argmax(vals, axis=1)
            cu = grid[np.arange(len(js)), best]
            np.maximum.at(per, js, vals[np.arange(len(js)), best])
            h /= 32.0
        per.setflags(write=False)
        memo[key] = (self.patches, per)
        return per.copy()

    def _nominal_distance(self, points: np.ndarray) -> np.ndarray:
        """``|nominal(points)|`` (mm) at 3-D points ``(m, 3)``: by the nominal's own unsigned
        ``distance`` when it has one (a family's :class:`~tabletcad.families.sweep.SweepNominal`, whose
        signed value is that distance with a side: the same numbers without the inside test)."""
        unsigned = getattr(self.nominal, "distance", None)
        return np.abs(unsigned(points) if unsigned is not None else self.nominal(points))

    def deviation_peaks(self, u: np.ndarray, v: np.ndarray, hv: float, peaks: int = 8, rounds: int = 3,
                        n: int = 9) -> np.ndarray:
        """Largest ``|nominal|`` (mm) on each patch: sampled on the grid ``u × v``, then polished around
        the ``peaks`` largest local maxima of the samples (of all patches together) and each patch's
        largest sample, each on ``n × n`` grids over one sample step each side (``u``'s step and
        ``hv``), four times finer each round (``rounds`` rounds): a peak is resolved 64 times finer
        than the grid.  The result is at least each patch's largest sample.  A :meth:`mirror` solid's
        twins lie as far from its nominal (whose faces are mirror images too) as their patches."""
        measured = self.measured()
        patches = [self.patches[i] for i in measured]
        G = np.empty((len(patches), 3, len(u), len(v)))  # each patch's grid written in its block, coordinates
        for k, p in enumerate(patches):  # first; then the points (x, y, z) in one transposed copy
            p.evaluate_grid(u, v, components=True, out=G[k])
        X = points_last(G.transpose(1, 0, 2, 3))  # (patches, nu, nv, 3)
        D = self._nominal_distance(X.reshape(-1, 3)).reshape(X.shape[:3])
        best = D.max(axis=(1, 2))
        t = self.trim
        E = np.pad(D, ((0, 0), (1, 1), (0, 0)), mode="edge")
        E = np.pad(E, ((0, 0), (0, 0), (1, 1)), mode="wrap" if t.full_v else "edge")
        local = np.ones(D.shape, dtype=bool)  # samples not below any of their eight neighbours
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                if di or dj:
                    local &= D >= E[:, 1 + di : E.shape[1] - 1 + di, 1 + dj : E.shape[2] - 1 + dj]
        idx = np.flatnonzero(local)
        idx = idx[np.argsort(D.reshape(-1)[idx])[::-1][:peaks]]
        per = D.reshape(len(D), -1).argmax(axis=1) + np.arange(len(D)) * D[0].size  # and each patch's largest
        idx = np.union1d(idx, per)
        which, i, j = np.unravel_index(idx, D.shape)
        centre = np.column_stack([u[i], v[j]]).astype(float)
        step = np.array([(u[-1] - u[0]) / max(len(u) - 1, 1), float(hv)])
        for _ in range(rounds):  # every peak's grid as scattered points, one evaluation per patch and round
            uu = clip(centre[:, :1, None] + linspace(-step[0], step[0], n)[None, :, None], t.u[0], t.u[1])
            vv = centre[:, 1:, None] + linspace(-step[1], step[1], n)[None, None, :]
            if not t.full_v:
                vv = clip(vv, t.v[0], t.v[1])
            uu, vv = np.broadcast_arrays(uu, vv)  # (peaks, n, n)
            pts = np.empty(uu.shape + (3,))
            for p in set(which.tolist()):  # a patch's peaks in one tensor grid; each keeps its diagonal block
                sel = np.flatnonzero(which == p)
                G = patches[p].evaluate_grid(uu[sel, :, 0].reshape(-1), vv[sel, 0, :].reshape(-1))
                for k, q in enumerate(sel):
                    pts[q] = G[k * n : (k + 1) * n, k * n : (k + 1) * n]
            g = self._nominal_distance(pts.reshape(-1, 3)).reshape(len(which), n * n)
            np.maximum.at(best, which, g.max(axis=1))
            top = np.argmax(g, axis=1)
            rows = np.arange(len(which))
            centre = np.column_stack([uu.reshape(len(which), -1)[rows, top], vv.reshape(len(which), -1)[rows, top]])
            step = step / 4.0
        m = self.mirror()
        if m is None:
            return best
        at = {i: k for k, i in enumerate(measured)}
        return np.array([best[at[min(i, j)]] for i, j in enumerate(m[1])])

    # ------------------------------------------------------------------ variants
    def trimmed(self, u=None, v=None, w=None) -> "Tablet":
        """The same tablet with parameter ranges restricted (see :class:`Trim`)."""
        t = self.trim
        return replace(self, trim=Trim(u or t.u, v or t.v, w or t.w))
