"""Inverse design: the band, thickness, cup depth (or, for the thesis's shapes, height or dome)
that gives a target volume or weight.

Any family of :data:`tabletcad.families.FAMILIES` (the industry families and the thesis's
shapes ``thesis.*``) and any custom outline (``functools.partial(outline_tablet, outline)``)
can be solved for each of its dimensions in :data:`VARY`; the other dimensions stay fixed.

Method
------
1. The volume: for a family with an exact nominal (:class:`~tabletcad.families.sweep.SweepNominal`:
   the industry families, custom outlines) the closed-form/quadrature
   :func:`~tabletcad.families.sweep.nominal_volume`; the family is only built as far as its
   nominal while searching (its PDE patches are made once, for the answer).  The thesis's
   shapes have no such nominal: their own :meth:`Tablet.volume() <tabletcad.geometry.tablet.Tablet.volume>`.
2. The feasible interval of the solved dimension: the families' constructors raise
   :class:`~tabletcad.errors.DesignError` on dimensions they cannot build, a tablet taller than
   ``tol.max_length`` is refused as a design file refuses it (a 10 mm concave round had been
   solved to a 999.7 mm band, 1001.5 mm tall), and with the other dimensions fixed the buildable
   values form one interval inside ``[0, tol.max_length]`` mm.  From a buildable start (the given value, else the family
   default, else the first buildable value of a logarithmic scan) its ends are found by
   doubling and then bisection on buildability, to ``1e-9`` relative (industry families,
   cheap) or ``1e-7`` relative (the thesis's shapes, whose every build makes patches).
   An open end (``band > 0``, ``thickness > 2 edge_radius``) is approached to that
   tolerance, so the reachable range is exact to it.
3. Monotonicity: the volume is sampled at 17 points across the interval.  Every family
   here is monotone in these dimensions (increasing, or decreasing for an oblong's dome);
   if the samples are not, the reachable range is the samples' span and the root is taken
   in the sampled sub-interval nearest the start.
4. :func:`scipy.optimize.brentq` on the bracket (``xtol`` 1e-12 mm), then one full build.

Steps 2-3 are remembered for the 32 latest (family, dimensions) requests, so solving several
targets for one design searches once.  A custom outline's inscribed radius is computed once
per request instead of on every build.

Weight (mg) = volume (mm³) × solid fraction × true density (mg/mm³).

::

    from tabletcad.families.inverse import solve_for

    r = solve_for("concave_round", target_weight_mg=350, vary="band", diameter=10, cup_depth=1,
                  solid_fraction=0.85, true_density_mg_mm3=1.5)
    r.value          # band (mm)
    r.tablet         # the tablet built with it
"""

from __future__ import annotations

import functools
import inspect
import math
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from tabletcad.errors import (MISSING, DesignError, GeometryError, check_finite, check_positive, check_range,
                              format_bound)
from tabletcad.families.family import lengths_unchecked
from tabletcad.families.sweep import NominalBuilt, SweepNominal, nominal_only, nominal_volume
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT
from tabletcad.tolerance import MAX_TRUE_DENSITY_MG_MM3, MIN_TRUE_DENSITY_MG_MM3

__all__ = ["InverseResult", "Reach", "reachable", "solve_for", "solvable", "VARY"]

#: Dimensions that can be solved for (each family takes some of them): the ones along the
#: tablet's axis, which a formulator changes at fixed tooling.  ``height`` (a spheroid's or
#: caplet's overall height) and ``dome`` (an oblong's or rod's dome) are the thesis's names.
VARY = ("band", "thickness", "cup_depth", "height", "dome")
_XTOL_MM = 1e-12  # brentq on the volume equation (mm)
_N_SAMPLES = 17  # volume samples across the feasible interval (monotonicity check)


@dataclass(frozen=True)
class InverseResult:
    """The solved parameter and the tablet it gives.

    Attributes
    ----------
    family, vary : str
    value : float
        The solved ``vary`` parameter, mm.
    params : dict
        All dimensions passed to the family (mm, deg), the solved one included.
    volume_mm3 : float
        Volume of the result (mm³): the exact nominal volume, or the tablet's own volume for a
        family without one (the thesis's shapes).
    weight_mg : float or None
        Weight at the given solid fraction and true density (mg).
    evaluations : int
        Family builds used (interval search, Brent and the final build; the interval search
        counts 0 when it was remembered from an earlier call with the same family and dimensions).
    tablet : Tablet
        The tablet built with the solved value.
    """

    family: str
    vary: str
    value: float
    params: dict
    volume_mm3: float
    weight_mg: float | None
    evaluations: int
    tablet: Tablet = field(repr=False, compare=False)


@dataclass(frozen=True)
class Reach:
    """The buildable interval of one dimension and the volumes it spans (the others fixed).

    Attributes
    ----------
    family, vary : str
    lo_mm, hi_mm : float
        Ends of the buildable interval (mm), within the search tolerance of an open end.
    volume_lo_mm3, volume_hi_mm3 : float
        Smallest and largest volume reached on the interval (mm³).
    monotone : bool
        Whether the sampled volumes are strictly monotone in the dimension.
    exact_nominal : bool
        Whether the volume is the exact nominal volume (else the tablet's own volume).
    """

    family: str
    vary: str
    lo_mm: float
    hi_mm: float
    volume_lo_mm3: float
    volume_hi_mm3: float
    monotone: bool
    exact_nominal: bool


# ---------------------------------------------------------------------------- families

def _family_function(family: str | Callable[..., Tablet]) -> Callable[..., Tablet]:
    """The constructor of a family name (any :data:`~tabletcad.families.FAMILIES` name, or an
    old name with its warning), or ``family`` itself if it is callable."""
    if callable(family):
        return family
    from tabletcad.families import family as lookup

    return lookup(family, parameter="family").func


def _family_name(family: str | Callable[..., Tablet], func: Callable[..., Tablet]) -> str:
    if isinstance(family, str):
        from tabletcad.families import RENAMED

        return RENAMED.get(family, family)
    inner = func.func if isinstance(func, functools.partial) else func
    name = getattr(inner, "__name__", "family")
    if name == "outline_tablet":
        return "custom_outline"
    from tabletcad.families import FAMILIES

    for key, fam in FAMILIES.items():  # a thesis function: its catalogue name
        if fam.func is inner:
            return key
    return name


def _takes(func: Callable[..., Tablet]) -> list[str]:
    params = inspect.signature(func).parameters
    return [k for k, p in params.items() if p.kind is p.POSITIONAL_OR_KEYWORD]


def solvable(family: str | Callable[..., Tablet]) -> tuple[str, ...]:
    """The dimensions of :data:`VARY` that ``family`` takes (what :func:`solve_for` can solve for).

    Parameters
    ----------
    family : str or callable
        A family name of :data:`tabletcad.families.FAMILIES` or a constructor.
    """
    takes = _takes(_family_function(family))
    return tuple(v for v in VARY if v in takes)


# ---------------------------------------------------------------------------- nominal-only builds

class _Probe:
    """Builds of ``func`` with one dimension varied: buildability and volume, cached by value."""

    def __init__(self, func: Callable[..., Tablet], dims: dict, vary: str) -> None:
        self.func, self.dims, self.vary = func, dims, vary
        # a length between 0 and min_length is refused by a design file (tabletcad.pipeline.design):
        # an approached lower end is raised to it, and a root between them is refused (solve_for)
        self.min_length = float(getattr(dims.get("tol", DEFAULT), "min_length", DEFAULT.min_length))
        # and one taller than the size limit (tabletcad.pipeline.design._check_height): not buildable here either
        self.max_height = float(getattr(dims.get("tol", DEFAULT), "max_length", DEFAULT.max_length)) * (1.0 + 1e-9)
        self.builds = 0
        self._cache: dict[float, tuple[bool, Any]] = {}
        self.exact_nominal: bool | None = None

    def _build(self, x: float) -> tuple[bool, Any]:
        if x not in self._cache:
            self.builds += 1
            try:
                with nominal_only(), lengths_unchecked():  # (a lower end approached is put on min_length below)
                    t = self.func(**self.dims, **{self.vary: x})
            except NominalBuilt as ready:
                self._cache[x] = (_height(ready.nominal) <= self.max_height, ready.nominal)
            except (DesignError, GeometryError):
                self._cache[x] = (False, None)
            else:
                self._cache[x] = (_height(t) <= self.max_height, t)
        return self._cache[x]

    def ok(self, x: float) -> bool:
        return self._build(x)[0]

    def volume(self, x: float) -> float:
        ok, obj = self._build(x)
        if not ok:  # pragma: no cover - only called inside the feasible interval
            raise DesignError(self.vary, x, "cannot be built with these dimensions", "mm")
        if isinstance(obj, SweepNominal):
            self.exact_nominal = True
            return nominal_volume(obj)
        if isinstance(obj.nominal, SweepNominal):  # pragma: no cover - built without the stop
            self.exact_nominal = True
            return nominal_volume(obj.nominal)
        self.exact_nominal = False
        return float(obj.volume())


def _height(built: SweepNominal | Tablet) -> float:
    """The height (mm) of a nominal-only build (its nominal thickness) or of a tablet (its extent in z)."""
    nominal = built if isinstance(built, SweepNominal) else getattr(built, "nominal", None)
    if isinstance(nominal, SweepNominal):
        return float(nominal.thickness)
    lo, hi = built.bounds()
    return float(hi[2] - lo[2])


def _start(probe: _Probe, x0: float, x_max: float) -> float:
    """A buildable value: ``x0`` if it is, else the one nearest it on a logarithmic scan."""
    if x0 > 0 and probe.ok(x0):
        return x0
    grid = np.geomspace(1e-6, x_max, 91)
    if x0 > 0:
        grid = grid[np.argsort(np.abs(np.log(grid / x0)))]
    for x in grid:
        if probe.ok(float(x)):
            return float(x)
    raise DesignError(probe.vary, x0, f"no {probe.vary} in (0, {x_max:g}] mm builds with these dimensions "
                      "(the other dimensions are infeasible together)", "mm")


def _ends(probe: _Probe, x0: float, x_max: float, rel: float) -> tuple[float, float]:
    """The buildable interval ``[lo, hi]`` around the buildable ``x0`` within ``[0, x_max]``."""
    # lower end: bisection between 0 and x0; 0 itself only if the values down to it build
    # (a compound cup builds flat at 0 but not below its least depth: {0} is not part of the interval)
    bad, good = 0.0, x0
    while good - bad > rel * x0:
        mid = 0.5 * (bad + good)
        if probe.ok(mid):
            good = mid
        else:
            bad = mid
    lo = 0.0 if bad == 0.0 and probe.ok(0.0) else good
    if 0.0 < lo < probe.min_length and probe.ok(probe.min_length):  # approached: the design files' least length
        lo = probe.min_length
    # upper end: doubling, then bisection
    good, bad = x0, None
    while good < x_max:
        nxt = min(2.0 * good, x_max)
        if probe.ok(nxt):
            good = nxt
        else:
            bad = nxt
            break
    if bad is not None:
        while bad - good > rel * max(good, x0):
            mid = 0.5 * (good + bad)
            if probe.ok(mid):
                good = mid
            else:
                bad = mid
    return lo, good


def _samples(lo: float, hi: float, x0: float) -> np.ndarray:
    """Points across ``[lo, hi]``: linear, plus logarithmic ones near ``lo`` for wide intervals."""
    xs = np.linspace(lo, hi, _N_SAMPLES)
    if hi > 0 and hi / max(lo, 1e-300) > 100.0:
        xs = np.concatenate([xs, np.geomspace(max(lo, hi * 1e-6), hi, _N_SAMPLES)])
    return np.unique(np.clip(np.append(xs, x0), lo, hi))


def _reach(probe: _Probe, name: str, x0: float, x_max: float, rel: float):
    x0 = _start(probe, x0, x_max)
    lo, hi = _ends(probe, x0, x_max, rel)
    xs = _samples(lo, hi, x0)
    vs = np.array([probe.volume(float(x)) for x in xs])
    dv = np.diff(vs)
    monotone = bool(np.all(dv > 0) or np.all(dv < 0)) if len(vs) > 1 else True
    reach = Reach(family=name, vary=probe.vary, lo_mm=lo, hi_mm=hi, volume_lo_mm3=float(vs.min()),
                  volume_hi_mm3=float(vs.max()), monotone=monotone, exact_nominal=bool(probe.exact_nominal))
    return reach, x0, xs, vs


# ---------------------------------------------------------------------------- API

def _interval(reach: Reach) -> str:
    """``[lo, hi]`` (a lower end > 0 is at least ``Tolerances.min_length``, a design file's least length),
    rounded into the interval."""
    return f"[{format_bound(reach.lo_mm, upper=False)}, {format_bound(reach.hi_mm, upper=True)}]"


def _prepare(family, vary, dims):
    func = _family_function(family)
    name = _family_name(family, func)
    takes = _takes(func)
    kw_only = {k for k, p in inspect.signature(func).parameters.items() if p.kind is p.KEYWORD_ONLY}
    if vary not in VARY or vary not in takes:
        allowed = [v for v in VARY if v in takes]
        raise DesignError("vary", vary, f"{name} can solve for {', '.join(allowed)}" if allowed else
                          f"{name} has none of the dimensions that can be solved for ({', '.join(VARY)})")
    for k in dims:
        if k not in takes and not (k in ("a", "tol") and k in kw_only):
            raise DesignError(k, dims[k], f"{name} takes {', '.join(takes)}")
    if isinstance(family, str):  # a named family needs what its design file needs (a callable: its defaults)
        from tabletcad.families import family as lookup

        fam = lookup(family, parameter="family")
        dims = {**fam.left_out({vary: None, **dims}), **dims}  # (a ffbe's bevel_width, given its bevel_depth)
        required = fam.required
        missing = [k for k in required if k != vary and k not in dims]
        if missing:
            raise DesignError(missing[0], MISSING, f"{name} needs {fam.needs(besides=vary)} besides {vary}")
    params = inspect.signature(func).parameters
    for k, v in dims.items():  # a dimension is a number: "10" is refused here, not as a failed search
        d = params[k].default if k in params else None
        if k not in ("a", "tol") and (d is inspect.Parameter.empty or (isinstance(d, (int, float)) and not isinstance(d, bool))):
            check_finite(k, v, "mm")
    dims = dict(dims)
    default = params[vary].default
    x0 = dims.pop(vary, default)
    x0 = float(x0) if isinstance(x0, (int, float)) and not isinstance(x0, bool) and math.isfinite(x0) else 0.0
    x_max = float(getattr(dims.get("tol", DEFAULT), "max_length", DEFAULT.max_length))
    return func, name, dims, x0, x_max


def _with_reach(func: Callable[..., Tablet]) -> Callable[..., Tablet]:
    """``functools.partial(outline_tablet, outline)`` with the outline's inscribed radius given
    (``reach=``): what the family would compute on every build (a minimisation), computed once."""
    from tabletcad.families.shaped import as_outline, outline_tablet

    if isinstance(func, functools.partial) and func.func is outline_tablet and len(func.args) == 1 \
            and "reach" not in func.keywords:
        try:
            outline = as_outline(func.args[0])
        except DesignError:  # the family's own build reports it
            return func
        return functools.partial(outline_tablet, outline, reach=outline.inscribed_radius(), **func.keywords)
    return func


_CACHE: OrderedDict = OrderedDict()
_CACHE_SIZE = 32


def _search(func: Callable[..., Tablet], name: str, dims: dict, vary: str, x0: float, x_max: float):
    """``(reach, start, samples, volumes, builds)``, remembered for the 32 latest hashable requests
    (the families are pure functions of their dimensions: solving several targets searches once)."""
    try:
        key = (func, name, vary, x0, x_max, tuple(sorted(dims.items())))
        hash(key)
    except TypeError:
        key = None
    if key is not None and key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key][:4] + (0,)
    probe = _Probe(_with_reach(func), dims, vary)
    rel = 1e-9 if _is_swept(probe, x0, x_max) else 1e-7
    found = _reach(probe, name, x0, x_max, rel)
    if key is not None:
        _CACHE[key] = found
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return found + (probe.builds,)


def reachable(family: str | Callable[..., Tablet], vary: str = "band", **dims: Any) -> Reach:
    """The buildable interval of ``vary`` (mm) and the volumes (mm³) it spans, the other dimensions fixed.

    Parameters
    ----------
    family : str or callable
        As for :func:`solve_for`.
    vary : str
        One of the family's dimensions in :data:`VARY`.
    **dims
        The other dimensions (mm, deg; the family's defaults otherwise), ``a`` and ``tol``.

    Returns
    -------
    Reach
    """
    func, name, dims, x0, x_max = _prepare(family, vary, dims)
    return _search(func, name, dims, vary, x0, x_max)[0]


def _is_swept(probe: _Probe, x0: float, x_max: float) -> bool:
    """Whether the family stops at an exact nominal (cheap builds), seen from one buildable value."""
    x = _start(probe, x0, x_max)
    return isinstance(probe._build(x)[1], SweepNominal)


def solve_for(
    family: str | Callable[..., Tablet],
    *,
    target_volume_mm3: float | None = None,
    target_weight_mg: float | None = None,
    vary: str = "band",
    solid_fraction: float | None = None,
    true_density_mg_mm3: float | None = None,
    **dims: Any,
) -> InverseResult:
    """The value of ``vary`` (mm) for which ``family(**dims)`` has the target volume or weight.

    Parameters
    ----------
    family : str or callable
        A family name of :data:`tabletcad.families.FAMILIES` (an industry family such as
        ``"capsule"``, or a thesis shape such as ``"thesis.shallow_convex_round"``) or its
        constructor; for any other plan outline, ``functools.partial(outline_tablet, outline)``
        (a custom_outline design).
    target_volume_mm3 : float, optional
        Target volume, mm³.
    target_weight_mg : float, optional
        Target weight, mg; needs ``solid_fraction`` (0, 1] and ``true_density_mg_mm3`` (mg/mm³).
        Give exactly one of the two targets.
    vary : {"band", "thickness", "cup_depth", "height", "dome"}
        The dimension to solve for (mm); the family must take it (:func:`solvable`).
    solid_fraction : float, optional
        1 - porosity, in (0, 1].
    true_density_mg_mm3 : float, optional
        True density of the material, mg/mm³ (= g/cm³).
    **dims
        The other dimensions (mm, deg): every one a named family's design file needs (a
        constructor passed as ``family`` uses its defaults for those not given), and ``a`` (the
        smoothing parameter) or ``tol`` if the constructor takes them.  A value given for
        ``vary`` is the start of the search (and, if the volume were not monotone, picks
        the root nearest it).

    Returns
    -------
    InverseResult
        The solved value (mm), all dimensions, the volume (mm³: exact nominal volume for the
        industry families and custom outlines, :meth:`Tablet.volume` for the thesis's shapes),
        the weight (mg) and the tablet built with the value.

    Raises
    ------
    DesignError
        Bad targets (``target_volume_mm3``, ``target_weight_mg``, ``solid_fraction``...), a
        ``vary`` the family does not take (``"vary"``; the message lists those it can solve
        for), an unknown dimension, or a target outside the volumes or weights the family can
        reach by changing ``vary`` alone: the message gives that range and the interval of
        ``vary`` (``target_volume_mm3 = 5 mm3 is not allowed: must be within 87.3 to 512.9
        mm3 for thickness in [1.6, 1000] mm ...``).
    """
    from scipy.optimize import brentq  # here: scipy.optimize takes ~0.4 s to import

    func, name, dims, x0, x_max = _prepare(family, vary, dims)
    if (target_volume_mm3 is None) == (target_weight_mg is None):
        raise DesignError("target", "both" if target_volume_mm3 is not None else "none",
                          "give exactly one of target_volume_mm3 and target_weight_mg")
    mg_per_mm3 = None
    if solid_fraction is not None or true_density_mg_mm3 is not None or target_weight_mg is not None:
        if solid_fraction is None or true_density_mg_mm3 is None:  # name the one left out
            missing = "solid_fraction" if solid_fraction is None else "true_density_mg_mm3"
            raise DesignError(missing, MISSING, "a weight needs both solid_fraction and true_density_mg_mm3")
        mg_per_mm3 = check_range("solid_fraction", solid_fraction, 0.0, 1.0, lo_open=True) * \
            check_range("true_density_mg_mm3", true_density_mg_mm3, MIN_TRUE_DENSITY_MG_MM3, MAX_TRUE_DENSITY_MG_MM3,
                        "mg/mm3")
    if target_volume_mm3 is not None:
        target = check_positive("target_volume_mm3", target_volume_mm3, "mm3")
    else:
        target = check_positive("target_weight_mg", target_weight_mg, "mg") / mg_per_mm3

    reach, x_start, xs, vs, builds = _search(func, name, dims, vary, x0, x_max)
    probe = _Probe(_with_reach(func), dims, vary)
    if target_weight_mg is None:
        param, given, unit, scale = "target_volume_mm3", target_volume_mm3, "mm3", 1.0
    else:
        param, given, unit, scale = "target_weight_mg", target_weight_mg, "mg", mg_per_mm3
    if not reach.volume_lo_mm3 <= target <= reach.volume_hi_mm3:
        basis = "" if reach.monotone else " (sampled: the volume is not monotone in it)"
        # the ends rounded into the range: each is accepted (rounded to 6 digits, 88.337 mg had been refused as
        # outside "88.337 to 100227 mg")
        raise DesignError(param, given, f"must be within {format_bound(reach.volume_lo_mm3 * scale, upper=False)} to "
                          f"{format_bound(reach.volume_hi_mm3 * scale, upper=True)} {unit} for {vary} in "
                          f"{_interval(reach)} mm{basis} ({name}, the other dimensions fixed)", unit)
    # a bracket: consecutive samples around the target (the one nearest the start if several)
    f = vs - target
    exact = np.flatnonzero(f == 0.0)
    if exact.size:
        x = float(xs[exact[np.argmin(np.abs(xs[exact] - x_start))]])
    else:
        brackets = np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))
        if brackets.size == 0:  # pragma: no cover - a non-monotone volume peaking between samples
            raise DesignError(param, given, f"no {vary} found for it: the volume of {name} is not monotone in {vary}",
                              unit)
        mids = 0.5 * (xs[brackets] + xs[brackets + 1])
        k = int(brackets[np.argmin(np.abs(mids - x_start))])
        # the bracket's ends are samples of the search: their volumes are known (brentq asks for both first)
        known = {float(xs[k]): float(vs[k]), float(xs[k + 1]): float(vs[k + 1])}
        x = float(brentq(lambda x: (known[x] if x in known else probe.volume(x)) - target, float(xs[k]),
                         float(xs[k + 1]), xtol=_XTOL_MM, rtol=4 * np.finfo(float).eps))
    if 0.0 < x < probe.min_length:  # between 0 (the flat face, where it builds) and a design file's least length
        raise DesignError(param, given, f"is reached only with {vary} = {x:.4g} mm, which a design file refuses "
                          f"(0 or at least {probe.min_length:g} mm, Tolerances.min_length)", unit)
    t = func(**dims, **{vary: x})  # the full build: patches (and, for the industry families, their certificate)
    v = nominal_volume(t.nominal) if isinstance(t.nominal, SweepNominal) else float(t.volume())
    return InverseResult(family=name, vary=vary, value=x, params={**{k: d for k, d in dims.items() if k not in ("a", "tol")}, vary: x},
                         volume_mm3=v, weight_mg=None if mg_per_mm3 is None else v * mg_per_mm3,
                         evaluations=builds + probe.builds + 1, tablet=t)
