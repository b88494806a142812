"""Inverse design: the band, thickness or cup depth that gives a target volume or weight.

The volume is the family's exact nominal volume (:func:`tabletcad.families.sweep.nominal_volume`,
independent of the PDE patches), and the root is found by
:func:`scipy.optimize.brentq` on a bracket found by growing the parameter from its
given (or default) value.  Weight (mg) = volume (mm³) × solid fraction × true
density (mg/mm³).

::

    from tabletcad.families.inverse import solve_for

    r = solve_for("concave_round", target_weight_mg=350, vary="band", diameter=10, cup_depth=1,
                  solid_fraction=0.85, true_density_mg_mm3=1.5)
    r.value          # band (mm)
    r.tablet         # the tablet built with it
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field
from typing import Any, Callable

from scipy.optimize import brentq

from tabletcad.errors import DesignError, check_positive, check_range
from tabletcad.families.sweep import SweepNominal, nominal_volume
from tabletcad.geometry.tablet import Tablet

__all__ = ["InverseResult", "solve_for", "VARY"]

#: Parameters that can be solved for (each family takes some of them).
VARY = ("band", "thickness", "cup_depth")
_XTOL_MM = 1e-9
_LO_MM = 1e-3  # the thinnest band / cup depth tried (mm)


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
        Exact nominal volume of the result.
    weight_mg : float or None
        Weight at the given solid fraction and true density.
    evaluations : int
        Family builds used (bracket + Brent).
    """

    family: str
    vary: str
    value: float
    params: dict
    volume_mm3: float
    weight_mg: float | None
    evaluations: int
    tablet: Tablet = field(repr=False, compare=False)


def _family_function(family: str | Callable[..., Tablet]) -> Callable[..., Tablet]:
    from tabletcad.families import FAMILY_FUNCTIONS

    by_name = {f.__name__: f for f in FAMILY_FUNCTIONS}
    if callable(family):
        return family
    if family not in by_name:
        raise DesignError("family", family, f"must be one of {', '.join(by_name)} (the industry families)")
    return by_name[family]


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
        An industry family name (``tabletcad shapes``) or its function; for any other plan
        outline, ``functools.partial(outline_tablet, outline)`` (a custom_outline design).
    target_volume_mm3, target_weight_mg : float
        Exactly one target; a weight needs ``solid_fraction`` (0, 1] and ``true_density_mg_mm3``.
    vary : {"band", "thickness", "cup_depth"}
        The dimension to solve for; the family must take it.
    **dims
        The other dimensions (mm; the family's defaults otherwise).  A value given for
        ``vary`` is the starting point of the bracket search.

    Raises
    ------
    DesignError
        Bad targets, a parameter the family does not take, or a target outside the volumes
        the family can reach by changing ``vary`` alone (the message gives that range).
    """
    func = _family_function(family)
    name = getattr(func, "__name__", None) or getattr(getattr(func, "func", None), "__name__", "family")
    takes = [k for k, p in inspect.signature(func).parameters.items() if p.kind is p.POSITIONAL_OR_KEYWORD]
    if vary not in VARY or vary not in takes:
        allowed = [v for v in VARY if v in takes]
        raise DesignError("vary", vary, f"{name} can solve for {', '.join(allowed) or 'none of ' + ', '.join(VARY)}")
    for k in dims:
        if k not in takes:
            raise DesignError(k, dims[k], f"{name} takes {', '.join(takes)}")
    if (target_volume_mm3 is None) == (target_weight_mg is None):
        raise DesignError("target", "both" if target_volume_mm3 is not None else "none",
                          "give exactly one of target_volume_mm3 and target_weight_mg")
    mg_per_mm3 = None
    if solid_fraction is not None or true_density_mg_mm3 is not None or target_weight_mg is not None:
        if solid_fraction is None or true_density_mg_mm3 is None:
            raise DesignError("solid_fraction, true_density_mg_mm3", "missing", "both are needed for a weight")
        mg_per_mm3 = check_range("solid_fraction", solid_fraction, 0.0, 1.0, lo_open=True) * \
            check_positive("true_density_mg_mm3", true_density_mg_mm3, "mg/mm3")
    if target_volume_mm3 is not None:
        target = check_positive("target_volume_mm3", target_volume_mm3, "mm3")
    else:
        target = check_positive("target_weight_mg", target_weight_mg, "mg") / mg_per_mm3
    x0 = float(dims.pop(vary, inspect.signature(func).parameters[vary].default))
    n = 0

    def volume(x: float) -> float:
        nonlocal n
        n += 1
        t = func(**dims, **{vary: x})
        if not isinstance(t.nominal, SweepNominal):  # pragma: no cover - every industry family sweeps
            raise DesignError("family", name, "has no exact nominal volume")
        return nominal_volume(t.nominal)

    def valid(x: float) -> float | None:
        try:
            return volume(x)
        except DesignError:
            return None

    lo = _LO_MM
    v_lo = valid(lo)
    if v_lo is None:
        raise DesignError(vary, lo, f"{name} cannot be built with {vary} = {lo} mm and these dimensions", "mm")
    hi, v_hi, bad = max(x0, 2 * lo), valid(max(x0, 2 * lo)), math.inf
    while v_hi is not None and v_hi < target and hi < 1e3:  # grow until the target is passed
        lo, v_lo = hi, v_hi
        hi *= 2.0
        v_hi = valid(hi)
    if v_hi is None:  # invalid: the largest buildable value lies between lo and hi
        bad = hi
        good, v_good = lo, v_lo
        for _ in range(40):
            mid = 0.5 * (good + bad)
            v = valid(mid)
            if v is None:
                bad = mid
            else:
                good, v_good = mid, v
                if v >= target:
                    break
        hi, v_hi = good, v_good
    if not (min(v_lo, v_hi) <= target <= max(v_lo, v_hi)):
        vmin = valid(_LO_MM)
        what = "volume_mm3" if target_weight_mg is None else "weight_mg"
        scale, unit = (1.0, "mm3") if target_weight_mg is None else (mg_per_mm3, "mg")
        raise DesignError(f"target_{what}", target_volume_mm3 if target_weight_mg is None else target_weight_mg,
                          f"{name} reaches {vmin * scale:.6g}-{v_hi * scale:.6g} {unit} by changing {vary} "
                          f"(the other dimensions fixed)", unit)
    x = brentq(lambda x: volume(x) - target, lo, hi, xtol=_XTOL_MM, rtol=1e-12)
    t = func(**dims, **{vary: x})
    v = nominal_volume(t.nominal)
    return InverseResult(family=name, vary=vary, value=float(x), params={**dims, vary: float(x)}, volume_mm3=v,
                         weight_mg=None if mg_per_mm3 is None else v * mg_per_mm3, evaluations=n + 1, tablet=t)
