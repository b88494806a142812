"""Problem files (TOML) for ``tabletcad optimise``.

A thesis problem::

    [problem]
    kind = "spherical_tablet"      # flat_faced_round | spherical_tablet | softgel_capsule
    method = "SLSQP"               # optional default: SLSQP | trust-constr | multistart | differential_evolution

    [parameters]                   # keyword arguments of tabletcad.optimise.thesis.<kind>_problem
    variant = "a"

    [solver]                       # optional: maxiter, ftol, fd_step, fd_scheme, starts, seed, popsize
    maxiter = 200

A problem over the parameters of any tablet family (``tabletcad shapes``)::

    [problem]
    kind = "family"
    family = "thesis.flat_faced_round"
    sense = "min"
    objective = "surface_area_mm2"   # or { linear = { diameter = 1.0, thickness = 1.0 } }

    [variables]
    diameter = { lower = 5.0, upper = 15.0, initial = 10.0 }
    thickness = { lower = 1.0, upper = 8.0, initial = 3.0 }

    [fixed]                          # other family parameters (optional)

    [[constraint]]
    quantity = "volume_mm3"          # volume_mm3 | surface_area_mm2 | plan_area_mm2 |
    target = 235.0                   #   length_mm | width_mm | height_mm | weight_mg
    relative = true                  # or lower = / upper = ; optional tol, scale

    [report]                         # for weight_mg: weight = volume x solid fraction x true density
    solid_fraction = 0.85
    true_density_mg_mm3 = 1.5

Instead of a volume constraint, ``[problem] solve_for = "band"`` (or ``thickness``,
``cup_depth``) with ``volume_mm3 = 235.0`` (or ``weight_mg = 300.0``, with the ``[report]``
table) builds every point with that parameter
solved for the volume (:func:`tabletcad.families.inverse.solve_for`, the family's
exact nominal volume): the variables then move along the designs of that volume.

Quantities are computed by :meth:`Tablet.properties` and :meth:`Tablet.dimensions`.

The finite-element breaking force (``fe`` extra) is the quantity
``fe_breaking_force_N``, as the objective or in a ``[[constraint]]``, with its
inputs in an ``[fe]`` table::

    [fe]
    tensile_strength_MPa = 2.0       # the formulation's tensile strength (required)
    direction = "width"              # width | length | x | y
    recheck = true                   # re-check the optimum on the default (finer) mesh
    symmetric = false                # true: every design is mirror symmetric across the load and
                                     # about mid-thickness (only its quarter is solved: faster, exactly symmetric)

Each evaluation is :func:`tabletcad.fe.objective.breaking_force` on the coarse
mesh; the re-check's figures go to the report's ``extras``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, Callable

from tabletcad.errors import MISSING, DesignError, format_bound, one_token
from tabletcad.tolerance import MAX_TENSILE_STRENGTH_MPA
from tabletcad.optimise.problem import METHODS, Constraint, Objective, Problem, Variable


__all__ = ["load_problem", "problem_from_dict", "family_problem", "QUANTITIES", "SOLVER_KEYS"]

_LAST_PROPERTIES: list = [None, None]


def _properties(t) -> dict:
    """``t.properties()`` computed once per design: the objective and the constraints of one
    point ask for volume and area of the same tablet in turn (one quadrature instead of two)."""
    if _LAST_PROPERTIES[0] is not t:
        _LAST_PROPERTIES[:] = [t, t.properties()]
    return _LAST_PROPERTIES[1]


QUANTITIES = {
    "volume_mm3": ("mm3", lambda t: _properties(t)["volume_mm3"]),
    "surface_area_mm2": ("mm2", lambda t: _properties(t)["surface_area_mm2"]),
    "plan_area_mm2": ("mm2", lambda t: t.plan_area()),
    "length_mm": ("mm", lambda t: t.dimensions()["length_mm"]),
    "width_mm": ("mm", lambda t: t.dimensions()["width_mm"]),
    "height_mm": ("mm", lambda t: t.dimensions()["height_mm"]),
}
_TOP = {"problem", "parameters", "solver", "variables", "fixed", "constraint", "fe", "report"}
#: The weight (mg): the volume times ``[report]`` solid_fraction and true_density_mg_mm3, as the design report's.
WEIGHT = "weight_mg"
_REPORT_KEYS = ("solid_fraction", "true_density_mg_mm3")
#: The FE quantity (needs the ``[fe]`` table and the ``fe`` extra).
FE_QUANTITY = "fe_breaking_force_N"
_FE_KEYS = {"tensile_strength_MPa", "direction", "recheck", "symmetric"}
#: A problem's ``name`` becomes a design and file name: a plain file name, no path.
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,99}")


# ---------------------------------------------------------------------------- strict value checks
def _shown(v: Any) -> Any:
    """A value as shown in an error line (huge integers and long strings shortened)."""
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) > 10**15:
        return f"{str(v)[:12]}... ({len(str(abs(v)))} digits)"
    if isinstance(v, str) and len(v) > 60:
        return v[:57] + "..."
    return v


def _range_text(lo, lo_open, hi, hi_open) -> str:
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    return " and ".join(parts)


def number(where: str, v: Any, unit: str = "", *, lo: float | None = None, lo_open: bool = False,
           hi: float | None = None, hi_open: bool = False) -> float:
    """A TOML number (int or float, never a string or boolean) within the given range."""
    rng = _range_text(lo, lo_open, hi, hi_open)
    allowed = "must be a finite number" + (f" {rng}" if rng else "") + (f" {unit}" if unit and rng else "")
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise DesignError(where, _shown(v), allowed, unit if isinstance(v, (int, float)) else "")
    try:
        x = float(v)
    except OverflowError:
        raise DesignError(where, _shown(v), allowed, unit) from None
    if not math.isfinite(x) or (lo is not None and (x < lo or (lo_open and x == lo))) or (
            hi is not None and (x > hi or (hi_open and x == hi))):
        raise DesignError(where, _shown(v), allowed, unit)
    return x


def integer(where: str, v: Any, lo: int, hi: int) -> int:
    """A TOML integer (never a float, string or boolean) in ``[lo, hi]``."""
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise DesignError(where, _shown(v), f"must be an integer >= {lo} and <= {hi}")
    return v


def boolean(where: str, v: Any) -> bool:
    """A TOML boolean (``true``/``false``; strings such as ``"false"`` are refused)."""
    if not isinstance(v, bool):
        raise DesignError(where, _shown(v), "must be a TOML boolean, true or false (unquoted)")
    return v


def choice(where: str, v: Any, allowed) -> str:
    if not isinstance(v, str) or v not in allowed:
        raise DesignError(where, _shown(v), "must be one of " + ", ".join(allowed))
    return v


def plain_name(where: str, v: Any) -> str:
    """A name used for files: letters, digits, ``_ . -``, no path, at most 100 characters."""
    if not isinstance(v, str) or not _NAME.fullmatch(v):
        raise DesignError(where, _shown(v), "must be a plain file name (letters, digits, _ . -; no path)")
    return v


def pair(where: str, v: Any, unit: str = "", *, lo: float = 0.0, lo_open: bool = True) -> tuple[float, float]:
    """Two numbers ``[lower, upper]`` with ``lo < lower <= upper <= LIMITS[unit]``."""
    if not isinstance(v, list) or len(v) != 2:
        raise DesignError(where, _shown(v), f"must be two numbers [lower, upper]{' in ' + unit if unit else ''}")
    hi = LIMITS.get(unit, 1e6)
    a = number(f"{where} lower", v[0], unit, lo=lo, lo_open=lo_open, hi=hi)
    b = number(f"{where} upper", v[1], unit, lo=lo, lo_open=lo_open, hi=hi)
    if a > b:
        raise DesignError(where, v, "must have lower <= upper", unit)
    return a, b


#: Largest accepted magnitude per unit: generous for tablets, small enough that nothing overflows or runs for minutes.
LIMITS = {"mm": 1000.0, "deg": 180.0, "mm2": 1e6, "mm3": 1e9, "mg": 1e9, "mg/mm3": 100.0, "MPa": 1e6, "N": 1e6, "": 1e6}


def _positive(unit: str = "") -> Callable[[str, Any], float]:
    return lambda w, v: number(w, v, unit, lo=0.0, lo_open=True, hi=LIMITS.get(unit, 1e6))


def _poisson(w: str, v: Any) -> float:
    return number(w, v, "", lo=0.0, hi=0.5, hi_open=True)


def _pairs(unit: str = "") -> Callable[[str, Any], tuple]:
    return lambda w, v: pair(w, v, unit)


def _choices(*allowed: str) -> Callable[[str, Any], str]:
    return lambda w, v: choice(w, v, allowed)


def _table(spec: dict) -> Callable[[str, Any], dict]:
    def check(w: str, v: Any) -> dict:
        _check_keys(w, v, set(spec))
        return {k: spec[k](f"{w} {k}", val) for k, val in v.items()}
    return check


def _initial(w: str, v: Any) -> dict:
    """Starting values by variable name (the names are checked against the problem's variables)."""
    if not isinstance(v, dict):
        raise DesignError(w, _shown(v), "must be a table of variable = starting value")
    return {k: number(f"{w} {k}", val, lo=-LIMITS[""], hi=LIMITS[""]) for k, val in v.items()}


#: Accepted ``[parameters]`` of the thesis problems (keyword arguments of ``thesis.<kind>_problem``).
THESIS_PARAMETERS: dict[str, dict[str, Callable[[str, Any], Any]]] = {
    "flat_faced_round": dict(
        mass_mg=_positive("mg"), true_density=_positive("mg/mm3"), E=_positive("MPa"), nu=_poisson,
        volume=_positive("mm3"), radius_bounds=_pairs("mm"), height_max=_positive("mm"), P_bounds=_pairs("MPa"),
        A_bounds=_pairs(), displacement=_choices("derived", "thesis"),
        omega_z0=lambda w, v: number(w, v, "mm", lo=-LIMITS["mm"], hi=LIMITS["mm"]),
        density=_choices("volume", "cylinder"), initial=_initial),
    "spherical_tablet": dict(
        variant=_choices("a", "b"), force_bounds=_pairs("N"), radius_bounds=_pairs("mm"), volume=_positive("mm3"),
        material=_table(dict(E=_positive("MPa"), nu=_poisson, s_y=_positive("MPa"))),
        reference_radius=_positive("mm"), initial=_initial),
    "softgel_capsule": dict(
        model=_choices("lame", "band", "none"), E=_positive("MPa"), nu=_poisson,
        P_int=lambda w, v: number(w, v, "MPa", lo=0.0, hi=LIMITS["MPa"]), radius_constraints=lambda w, v: boolean(w, v),
        initial=_initial),
}

#: ``[solver]`` options and their checks (the keyword arguments of :func:`~tabletcad.optimise.solve`).
SOLVER_KEYS: dict[str, Callable[[str, Any], Any]] = {
    "maxiter": lambda w, v: integer(w, v, 1, 100_000),
    "ftol": lambda w, v: number(w, v, lo=0.0, lo_open=True, hi=1.0, hi_open=True),
    "fd_step": lambda w, v: number(w, v, lo=0.0, lo_open=True, hi=0.1),
    "fd_scheme": _choices("forward", "central"),
    "starts": lambda w, v: integer(w, v, 0, 10_000),
    "seed": lambda w, v: integer(w, v, 0, 2**32 - 1),
    "popsize": lambda w, v: integer(w, v, 1, 1000),
}


def load_problem(path: str | Path) -> tuple[Problem, str, dict]:
    """Read a problem file; return ``(problem, default method, solver options)``."""
    from tabletcad.io.tomlfile import read_toml_file

    return problem_from_dict(read_toml_file(path, "problem file"))


def _check_keys(where: str, table: Any, allowed: set) -> dict:
    if not isinstance(table, dict):
        raise DesignError(where, _shown(table), "must be a table")
    for k in table:
        if k not in allowed:
            raise DesignError(f"{where} key {_shown(k)!r}", _shown(table[k]),
                              f"allowed keys are {', '.join(sorted(allowed)) or '(none)'}")
    return table


def problem_from_dict(data: dict) -> tuple[Problem, str, dict]:
    _check_keys("top-level", data, _TOP)
    prob = _check_keys("[problem]", data.get("problem", {}), {"kind", "method", "family", "sense", "objective", "name",
                                                              "solve_for", "volume_mm3", WEIGHT})
    kind = prob.get("kind")
    kinds = (*THESIS_PARAMETERS, "family")
    if kind is None:
        raise DesignError("[problem] kind", MISSING, "must be one of " + ", ".join(kinds))
    choice("[problem] kind", kind, kinds)
    method = choice("[problem] method", prob.get("method", "SLSQP"), METHODS)
    if "sense" in prob:
        choice("[problem] sense", prob["sense"], ("max", "min"))
    if "name" in prob:
        plain_name("[problem] name", prob["name"])
    solver_table = _check_keys("[solver]", data.get("solver", {}), set(SOLVER_KEYS))
    solver = {k: SOLVER_KEYS[k](f"[solver] {k}", v) for k, v in solver_table.items()}
    for key, readers in (("starts", ("multistart",)), ("popsize", ("differential_evolution",)),
                         ("seed", ("multistart", "differential_evolution"))):
        if key in solver and method not in readers:  # a setting the file's own method would ignore
            raise DesignError(f"[solver] {key}", solver[key], f"is read by method {' or '.join(readers)} only "
                              f"(this file's method: {method})")
    if kind == "family":
        for k in ("parameters",):
            if k in data:
                raise DesignError(f"[{k}]", "given", "family problems take [variables], [fixed] and [[constraint]]")
        return family_problem(prob, data.get("variables"), data.get("fixed", {}), data.get("constraint", []),
                              data.get("fe"), data.get("report")), method, solver
    for k in ("variables", "fixed", "constraint", "fe", "report"):
        if k in data:
            raise DesignError(f"[{k}]", "given", f"only family problems take it, not {kind!r}")
    for k in ("family", "sense", "objective", "name", "solve_for", "volume_mm3", WEIGHT):
        if k in prob:
            raise DesignError(f"[problem] {k}", _shown(prob[k]), f"only family problems take it, not {kind!r}")
    spec = THESIS_PARAMETERS[kind]
    params = _check_keys("[parameters]", data.get("parameters", {}), set(spec))
    params = {k: spec[k](f"[parameters] {k}", v) for k, v in params.items()}
    from tabletcad.optimise import thesis  # the PDE core: imported once the file is known to be valid

    try:
        return thesis.make_problem(kind, **params), method, solver
    except DesignError as exc:
        if exc.parameter.startswith("initial."):  # name the table the key came from
            raise exc.renamed(f"parameters.{exc.parameter}") from None
        raise


def _fe_settings(fe: Any, used: bool) -> dict | None:
    """The checked ``[fe]`` table (None when no FE quantity is used; refused when given unused)."""
    if fe is None:
        if used:
            raise DesignError("[fe] tensile_strength_MPa", MISSING,
                              f"must be given (MPa) when {FE_QUANTITY} is the objective or a constraint")
        return None
    _check_keys("[fe]", fe, _FE_KEYS)
    if not used:
        raise DesignError("[fe]", "given", f"only problems using {FE_QUANTITY} take it")
    if "tensile_strength_MPa" not in fe:
        raise DesignError("[fe] tensile_strength_MPa", MISSING, "must be given (MPa)")
    return {
        # (the FE's own range: 5000 MPa had passed here and failed the run after its first build, exit 3)
        "tensile_strength_MPa": number("[fe] tensile_strength_MPa", fe["tensile_strength_MPa"], "MPa", lo=0.0,
                                       lo_open=True, hi=MAX_TENSILE_STRENGTH_MPA),
        "direction": choice("[fe] direction", fe.get("direction", "width"), ("width", "length", "x", "y")),
        "recheck": boolean("[fe] recheck", fe.get("recheck", True)),
        "symmetric": boolean("[fe] symmetric", fe.get("symmetric", False)),
    }


def _fe_recheck(settings: dict) -> Callable[[dict, Any], dict]:
    """``extras``: the optimum's FE breaking force on the coarse mesh and on the default (finer) one."""
    def extras(x: dict, design: Any) -> dict:
        from tabletcad.fe.objective import breaking_force

        st, d = settings["tensile_strength_MPa"], settings["direction"]
        coarse = breaking_force(design, st, d, symmetric=settings["symmetric"])
        fine = breaking_force(design, st, d, coarse=False, symmetric=settings["symmetric"])
        return {"fe_breaking_force_coarse_N": coarse, "fe_breaking_force_fine_N": fine,
                "fe_fine_minus_coarse_relative": fine / coarse - 1.0}
    return extras


def _uses(prob: dict, constraints: Any, quantity: str) -> bool:
    """True when ``quantity`` is the problem's objective or one of its constraints' quantity."""
    return prob.get("objective") == quantity or (isinstance(constraints, list) and any(
        isinstance(c, dict) and c.get("quantity") == quantity for c in constraints))


def _weight_basis(report: Any, used: bool) -> float | None:
    """``solid fraction x true density`` (mg/mm³) from the ``[report]`` table, the factor from volume to weight,
    checked as a design's ``[report]`` table is (the optimum's design file carries it); None when there is no
    table (refused when a weight is asked for)."""
    if report is None:
        if used:
            raise DesignError("[report] solid_fraction", MISSING, f"must be given with true_density_mg_mm3 when "
                              f"{WEIGHT} is the objective, a constraint or the held quantity")
        return None
    from tabletcad.pipeline.designreport import ReportOptions

    _check_keys("[report]", report, set(_REPORT_KEYS))
    for k in _REPORT_KEYS:
        if k not in report:
            raise DesignError(f"[report] {k}", MISSING, f"must be given with {', '.join(_REPORT_KEYS)}")
    opts = ReportOptions.from_table(dict(report))  # numbers in the design's ranges
    return opts.solid_fraction * opts.true_density_mg_mm3


def _held_volume(prob: dict, fam_name: str, fam: Any, variables: dict, fixed: dict,
                 basis: float | None = None) -> tuple[str, float] | None:
    """``(parameter, volume mm³)`` when ``[problem] solve_for`` holds the volume (or the weight: ``basis`` is
    solid fraction x true density, mg/mm³) by solving one parameter."""
    held = [k for k in ("volume_mm3", WEIGHT) if k in prob]
    if "solve_for" not in prob and not held:
        return None
    if len(held) > 1:
        raise DesignError(f"[problem] {WEIGHT}", prob[WEIGHT], "must not be given with volume_mm3: hold one of them")
    if "solve_for" not in prob or not held:
        missing = "solve_for" if "solve_for" not in prob else "volume_mm3"
        raise DesignError(f"[problem] {missing}", MISSING, "solve_for and volume_mm3 (or weight_mg) go together")
    from tabletcad.families.inverse import VARY

    vary = choice("[problem] solve_for", prob["solve_for"], tuple(v for v in VARY if v in fam.params))
    if vary in variables or vary in fixed:
        raise DesignError("[problem] solve_for", vary, "must not be a variable or fixed: it is solved for the volume")
    if held[0] == WEIGHT:
        weight = number(f"[problem] {WEIGHT}", prob[WEIGHT], "mg", lo=0.0, lo_open=True, hi=LIMITS["mg"])
        return vary, weight / basis
    return vary, number("[problem] volume_mm3", prob["volume_mm3"], "mm3", lo=0.0, lo_open=True, hi=LIMITS["mm3"])


def _check_lower_lengths(fam_name: str, fam: Any, vs: list, fixed: dict) -> None:
    """Refuse a length variable's lower bound that no design file takes: between 0 and
    ``Tolerances.min_length`` (a solver ending on it wrote an optimum that could not be built), or 0
    where the family refuses 0 for it (a band); checked by building at that bound, the other variables
    at their starting values or mid-range."""
    from tabletcad.tolerance import DEFAULT as TOL

    start = {v.name: v.initial if v.initial is not None else 0.5 * (v.lower + v.upper) for v in vs}
    for v in vs:
        if v.unit != "mm" or v.lower >= TOL.min_length:
            continue
        try:
            fam.build(**fixed, **{**start, v.name: 0.0})
            refused = None
        except DesignError as exc:
            refused = exc if exc.parameter == v.name else None
        if v.lower > 0.0:  # (a family that refuses 0 for it: "0 or at least" would offer a bound it refuses)
            raise DesignError(f"[variables] {v.name} lower", v.lower, f"must be {'' if refused else '0 or '}at least "
                              f"{TOL.min_length:g} mm (Tolerances.min_length, the least length a design takes)", "mm")
        if refused is not None:
            raise DesignError(f"[variables] {v.name} lower", 0.0, f"family {fam_name!r} refuses {v.name} = 0 "
                              f"({refused.allowed}): give a lower bound of at least {TOL.min_length:g} mm", "mm")


def _warn_unbuildable_upper(fam_name: str, vs: list, start: dict, build: Callable[[dict], Any]) -> None:
    """Warn of an upper bound the family refuses for that variable at the start's other values (a cup deeper
    than half the diameter): designs past that limit do not build, and an optimum on it is then reported
    as not converged.  A warning, not a refusal: the limit may move with the other variables."""
    import warnings

    for v in vs:
        try:
            build({**start, v.name: v.upper})
        except DesignError as exc:
            if exc.parameter == v.name:
                unit = f" {v.unit}" if v.unit else ""
                warnings.warn(f"[variables] {v.name} upper = {v.upper:g}{unit}: family {fam_name!r} refuses it at the "
                              f"start's other values ({exc.allowed}); designs past that limit do not build, and an "
                              "optimum on it is reported as not converged", UserWarning, stacklevel=2)
        except Exception:  # noqa: BLE001 - any other failure there is the optimiser's to meet and report
            pass


def family_problem(prob: dict, variables: Any, fixed: dict, constraints: Any, fe: Any = None,
                   report: Any = None) -> Problem:
    """A :class:`Problem` over the parameters of a tablet family (:data:`tabletcad.families.FAMILIES`).

    ``fe`` is the ``[fe]`` table, needed when :data:`FE_QUANTITY` is the objective or a constraint;
    ``report`` the ``[report]`` table (solid fraction and true density), needed when :data:`WEIGHT` is used.
    """
    from tabletcad.pipeline.design import design_to_toml, toml_text
    from tabletcad.families import FAMILIES, RENAMED
    from tabletcad.tolerance import DEFAULT as TOL
    from tabletcad.families import family as lookup_family

    fam_name = prob.get("family")
    if isinstance(fam_name, str) and fam_name in RENAMED:
        fam_name = lookup_family(fam_name, parameter="[problem] family").name
    fam_name = choice("[problem] family", fam_name, tuple(FAMILIES))
    fam = FAMILIES[fam_name]
    if not isinstance(variables, dict) or not variables:
        raise DesignError("[variables]", _shown(variables), "must be a table of family parameters with lower/upper/initial")
    vs = []
    for name, spec in variables.items():
        if name not in fam.params:
            raise DesignError(f"[variables] {_shown(name)}", _shown(spec), f"family {fam_name!r} takes {', '.join(fam.params)}")
        _check_keys(f"[variables] {name}", spec, {"lower", "upper", "initial"})
        if "lower" not in spec or "upper" not in spec:
            raise DesignError(f"[variables] {name}", spec, "needs lower and upper")
        unit = fam.params[name]
        lim = LIMITS.get(unit, LIMITS[""])
        lo = number(f"[variables] {name} lower", spec["lower"], unit, lo=0.0, hi=lim)
        hi = number(f"[variables] {name} upper", spec["upper"], unit, lo=0.0, hi=lim)
        x0 = None if "initial" not in spec else number(f"[variables] {name} initial", spec["initial"], unit, lo=0.0, hi=lim)
        if hi < lo:  # named by the file's key (the Variable would say "variable NAME bounds")
            raise DesignError(f"[variables] {name} upper", hi, f"must be >= lower = {format_bound(lo, upper=False)}", unit)
        vs.append(Variable(name, lo, hi, x0, unit, least=TOL.min_length if unit == "mm" else None))
    both = [k for k in fixed if k in variables] if isinstance(fixed, dict) else []
    if both:  # (else: "allowed keys are (none)", as if the family had no such parameter)
        raise DesignError(f"[fixed] {both[0]}", _shown(fixed[both[0]]), "must not also be in [variables]: "
                          "a parameter is either varied or fixed")
    _check_keys("[fixed]", fixed, set(fam.params) - set(variables))
    fixed = {k: number(f"[fixed] {k}", v, fam.params[k], lo=0.0, hi=LIMITS.get(fam.params[k], LIMITS[""]))
             for k, v in fixed.items()}
    if "sense" not in prob:  # no default: one left out would silently pick the other extreme
        raise DesignError("[problem] sense", MISSING, "must be given for a family problem: 'min' or 'max'")
    sense = prob["sense"]
    name = prob.get("name", f"{fam_name}_optimum")
    weighs = _uses(prob, constraints, WEIGHT) or WEIGHT in prob
    basis = _weight_basis(report, weighs)  # (a table without a weight to read it: refused below, once the
    held = _held_volume(prob, fam_name, fam, variables, fixed, basis)  # quantities' names are known good)
    _check_lower_lengths(fam_name, fam, vs, fixed)
    given = set(variables) | set(fixed) | ({held[0]} if held else set())
    fixed.update(fam.left_out({**dict.fromkeys(given), **fixed}))  # (a ffbe's bevel_width, given its bevel_depth)
    missing = [k for k in fam.required if k not in given and k not in fixed]
    if missing:  # the family's default would stand in for it, unseen, and the optimum would not build
        raise DesignError(f"[fixed] {missing[0]}", MISSING, f"family {fam_name!r} needs {fam.needs()}: "
                          "give each as a variable, in [fixed] or as [problem] solve_for")

    def build(x):
        from tabletcad.families.family import lengths_unchecked

        # a solver passes through lengths below Tolerances.min_length on its way to 0 (a land) and puts
        # its optimum on 0 or the least length itself (solvers.py): the constructors build them here
        with lengths_unchecked():
            if held is None:
                return fam.build(**fixed, **x)
            from tabletcad.families.inverse import solve_for

            vary, volume = held
            return solve_for(fam_name, target_volume_mm3=volume, vary=vary, **fixed, **x).tablet

    obj_spec = prob.get("objective")
    fe_set = _fe_settings(fe, _uses(prob, constraints, FE_QUANTITY))
    start = {v.name: v.initial if v.initial is not None else 0.5 * (v.lower + v.upper) for v in vs}
    try:  # the start must build: a value in the file that the family refuses there is the file's error
        first = build(start)
    except DesignError as exc:
        if held is not None and exc.parameter == "target_volume_mm3":  # no design of the start has that volume
            if WEIGHT in prob:
                raise DesignError(f"[problem] {WEIGHT}", prob[WEIGHT], f"at the start's dimensions its volume "
                                  f"{held[1]:g} mm3 {exc.allowed}", "mg") from None
            raise DesignError("[problem] volume_mm3", held[1], f"at the start's dimensions it {exc.allowed}", "mm3") from None
        at = ", ".join(f"{k} = {v:g}" for k, v in start.items())
        if exc.parameter in fixed:
            raise DesignError(f"[fixed] {exc.parameter}", exc.value, f"{exc.allowed} (at the start: {at}; give "
                              "variables an initial value at which the design builds)", exc.unit) from None
        if exc.parameter in start:
            raise DesignError(f"[variables] {exc.parameter} initial", exc.value, f"{exc.allowed} (the start: {at})",
                              exc.unit) from None
        first = None  # any other failure of the start is the optimiser's to report
    if first is not None:
        _warn_unbuildable_upper(fam_name, vs, start, build)
    if first is not None and fe_set is not None and fe_set["symmetric"]:
        from tabletcad.fe.diametral import check_symmetric

        # a quarter model of another shape: refused before any solve (a family's symmetry does not
        # change with its dimensions)
        check_symmetric(first, fe_set["direction"], "[fe] symmetric")
    quantities = dict(QUANTITIES)
    if basis is not None:
        quantities[WEIGHT] = ("mg", lambda t: _properties(t)["volume_mm3"] * basis)
    if fe_set is not None:
        from tabletcad.optimise.strength import fe_breaking_force

        quantities[FE_QUANTITY] = ("N", fe_breaking_force(fe_set["tensile_strength_MPa"], fe_set["direction"],
                                                          fe_set["symmetric"]))
    if isinstance(obj_spec, str):
        if obj_spec not in quantities:
            raise DesignError("[problem] objective", obj_spec, "must be one of " + ", ".join([*QUANTITIES, WEIGHT, FE_QUANTITY])
                              + " or {linear = {...}}")
        unit, f = quantities[obj_spec]
        objective = Objective(f, obj_spec, unit)
    elif isinstance(obj_spec, dict) and set(obj_spec) == {"linear"} and isinstance(obj_spec["linear"], dict):
        coef = {k: number(f"[problem] objective linear {k}", v, lo=-LIMITS[""], hi=LIMITS[""]) for k, v in obj_spec["linear"].items()}
        for k in coef:
            if k not in variables:
                raise DesignError("[problem] objective linear", k, "must name variables")
        objective = Objective(lambda t: sum(c * float(t.params[k]) for k, c in coef.items()),
                              " + ".join(f"{c:g} {k}" for k, c in coef.items()), "", grad=lambda x, d: dict(coef))
    else:
        raise DesignError("[problem] objective", _shown(obj_spec), "must be a quantity name or {linear = {variable = coefficient}}")
    if not isinstance(constraints, list):
        raise DesignError("[[constraint]]", _shown(constraints), "must be an array of tables")
    cons = []
    for k, c in enumerate(constraints):
        _check_keys(f"[[constraint]] {k}", c, {"quantity", "target", "lower", "upper", "relative", "tol", "scale", "name"})
        q = choice(f"[[constraint]] {k} quantity", c.get("quantity"), tuple(dict.fromkeys(
            (*QUANTITIES, WEIGHT, FE_QUANTITY) if not fe_set else (*quantities, WEIGHT))))
        unit, f = quantities[q]
        # every quantity is a size (>= 0): a target must be > 0, bounds >= 0
        kw = {kk: number(f"[[constraint]] {k} {kk}", c[kk], unit, lo=0.0, lo_open=kk == "target", hi=LIMITS[unit])
              for kk in ("target", "lower", "upper") if kk in c}
        kw.update({kk: number(f"[[constraint]] {k} {kk}", c[kk], "" if kk == "tol" else unit, lo=0.0, lo_open=True,
                              hi=LIMITS["" if kk == "tol" else unit]) for kk in ("tol", "scale") if kk in c})
        if "lower" in kw and "upper" in kw and kw["upper"] < kw["lower"]:  # named by the file's key, as a variable's
            # (the Constraint would say "constraint[1].bounds = (5.0, 4.0)", a key the file does not have)
            raise DesignError(f"[[constraint]] {k} upper", kw["upper"],
                              f"must be >= lower = {format_bound(kw['lower'], upper=False)}", unit)
        relative = boolean(f"[[constraint]] {k} relative", c["relative"]) if "relative" in c else False
        cname = c.get("name", q)
        if not isinstance(cname, str) or not cname.strip() or "\n" in cname:
            raise DesignError(f"[[constraint]] {k} name", _shown(cname), "must be a one-line text")
        try:
            cons.append(Constraint(cname, f, kind="eq" if "target" in c else "ineq", relative=relative, unit=unit, **kw))
        except DesignError as exc:  # "constraint NAME lower": the file's [[constraint]] k
            raise exc.renamed(f"constraint[{k}]" + exc.parameter[len(one_token(f"constraint {cname}")):]) from None

    if report is not None and not weighs:
        raise DesignError("[report]", "given", f"only problems using {WEIGHT} take it")

    def to_toml(x, d):
        solved = {} if held is None else {held[0]: float(d.params[held[0]])}
        # the weight's basis goes with the optimum, so its build reports the weight it was optimised for
        extra = "" if report is None else "\n" + toml_text({"report": {k: report[k] for k in _REPORT_KEYS}})
        return design_to_toml(fam_name, {**fixed, **x, **solved}, name=name, extra=extra)

    extras = _fe_recheck(fe_set) if fe_set is not None and fe_set["recheck"] else None
    return Problem(name=name, variables=vs, objective=objective, sense=sense, constraints=cons, build=build,
                   to_toml=to_toml, description=f"family {fam_name}: {sense} {objective.name}" + (
                       "" if held is None else f"; {held[0]} solved for the family's nominal volume {held[1]:g} mm3"
                       + (f" ({prob[WEIGHT]:g} mg)" if WEIGHT in prob else "") + " "
                       "(the PDE surface's volume is within its certified deviation of it)"), extras=extras)
