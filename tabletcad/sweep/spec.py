"""Sweep files: a base design, the keys to vary and how to sample them.

A sweep file is TOML::

    [design]                     # an ordinary design: [design.tablet], [design.report], ...
    [design.tablet]
    family = "concave_round"
    diameter = 10.0
    band = 2.8
    cup_depth = 0.9

    [sweep]
    method = "grid"              # or "lhs" (Latin hypercube) with samples and seed
    outputs = ["report"]         # optionally also "step", "stl", "glb", "png", "tooling"

    [sweep.vary]
    "tablet.cup_depth" = { min = 0.5, max = 1.2, num = 8 }   # mm, inclusive end points
    "tablet.band" = [2.4, 2.8, 3.2]                           # mm, the values themselves

A grid takes every combination (:func:`itertools.product`, the first key
varying slowest, values in the order given; range values are
:func:`numpy.linspace` rounded to 12 significant digits).  A Latin hypercube
(:class:`scipy.stats.qmc.LatinHypercube` with the file's ``seed``) draws
``samples`` points in the unit cube; a ``{min, max}`` range maps ``x`` to
``min + x (max - min)`` and a list picks the value at ``floor(x n)``.

Every problem with the file is a :class:`~tabletcad.errors.DesignError`
raised by :func:`parse_sweep` before any design is built.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tabletcad.errors import MISSING, DesignError, format_bound


__all__ = ["SweepSpec", "Axis", "OUTPUTS", "load_sweep", "parse_sweep", "design_hash", "set_key"]

# outputs a design may produce besides its report -> the files of `tabletcad build` they stand for
OUTPUTS = {
    "report": (),
    "step": ("tablet.step",),
    "stl": ("tablet.stl",),
    "glb": ("tablet.glb",),
    "png": ("tablet.png",),
    # (every tool set's; complete punches add their drawing, a scored or embossed tablet its plain one:
    # tabletcad.tooling.stage.tooling_outputs, which a design's build collects)
    "tooling": ("assembly.step", "upper_punch.step", "lower_punch.step", "die.step", "drawing.svg", "drawing.pdf",
                "drawing.dxf"),
}
_SWEEP_KEYS = {"method", "samples", "seed", "outputs", "vary", "store"}


#: most designs one sweep file may give (a million reports take hours; a grid of 1e8 x 1e8 filled memory)
MAX_DESIGNS = 1_000_000


@dataclass(frozen=True)
class Axis:
    """One varied key: the dotted ``key`` of the design and its ``values`` (grid) or range (lhs).

    ``values`` is the list of values for a list axis or a grid range (``num``
    points from ``lo`` to ``hi``, end points included); ``lo``/``hi`` are set
    for ``{min, max}`` ranges (units of the design key).
    """

    key: str
    values: tuple[Any, ...] = ()
    lo: float | None = None
    hi: float | None = None

    def pick(self, x: float) -> Any:
        """The value at ``x`` in [0, 1) of a Latin hypercube sample."""
        if self.lo is not None and self.hi is not None:
            return self.lo + x * (self.hi - self.lo)
        n = len(self.values)
        return self.values[min(int(math.floor(x * n)), n - 1)]


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep: the base ``design`` dict, its ``axes``, sampling and ``outputs``."""

    design: dict[str, Any]
    axes: tuple[Axis, ...]
    method: str = "grid"
    samples: int | None = None
    seed: int | None = None
    outputs: tuple[str, ...] = ("report",)
    store: str | None = None
    name: str = "sweep"
    keys: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "keys", tuple(a.key for a in self.axes))

    def points(self) -> list[tuple[Any, ...]]:
        """The varied values of every design, in the sweep's deterministic order."""
        if self.method == "grid":
            return list(itertools.product(*(a.values for a in self.axes)))
        from scipy.stats import qmc

        x = qmc.LatinHypercube(d=len(self.axes), seed=self.seed).random(self.samples)
        return [tuple(a.pick(float(xi)) for a, xi in zip(self.axes, row)) for row in x]

    def designs(self) -> list[dict[str, Any]]:
        """The design dict of every point (the base design with the varied keys set)."""
        out = []
        for values in self.points():
            d = copy.deepcopy(self.design)
            for key, v in zip(self.keys, values):
                set_key(d, key, v)
            out.append(d)
        return out


def set_key(design: dict, key: str, value: Any) -> None:
    """Set the dotted ``key`` (``"tablet.cup_depth"``) of a design dict in place."""
    *path, leaf = key.split(".")
    node = design
    for p in path:
        node = node.setdefault(p, {})
    node[leaf] = value


def design_hash(design: dict[str, Any]) -> str:
    """A stable 16-hex-digit SHA-256 of a design dict (keys sorted, floats by ``repr``)."""
    text = json.dumps(design, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and check a sweep file (see module docstring)."""
    from tabletcad.io.tomlfile import read_toml_file

    path = Path(path)
    return parse_sweep(read_toml_file(path, "sweep file"), name=path.stem)


def _number(where: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
        raise DesignError(where, v, "must be a finite number")
    return float(v)


def _family_of(design: dict):
    """The named family of ``[design.tablet]`` (:data:`tabletcad.families.FAMILIES`), or ``None``."""
    from tabletcad.families import FAMILIES, RENAMED

    tab = design.get("tablet", {})
    fam = tab.get("family") if isinstance(tab, dict) else None
    fam = RENAMED.get(fam, fam) if isinstance(fam, str) else fam
    return FAMILIES.get(fam) if isinstance(fam, str) else None


def _dimension_keys(design: dict) -> set[str]:
    """The dotted keys whose values are numbers in every design: the named family's parameters."""
    fam = _family_of(design)
    return set() if fam is None else {f"tablet.{k}" for k in fam.params}


def _check_family(design: dict, varied: set[str]) -> None:
    """Refuse, when the sweep does not vary it, a ``[design.tablet]`` family that no design takes (none
    given, not text, an unknown name) and a required dimension of the family that is neither given
    nor varied: every row would fail (a trial: such sweeps ran, each row an error, and exited 0)."""
    import warnings

    from tabletcad.families import family

    tab = design["tablet"]
    if "tablet.family" in varied:
        return  # each value of the axis is a family of its own rows
    if "family" not in tab:
        raise DesignError("design.tablet.family", MISSING, "must name the tablet's family (tabletcad shapes lists them)")
    if tab["family"] in ("free_form", "custom_outline"):
        return
    with warnings.catch_warnings():  # (an old name: each design warns as it is built)
        warnings.simplefilter("ignore", FutureWarning)
        fam = family(tab["family"], parameter="design.tablet.family")
    given = {**tab, **{k.split(".", 1)[1]: None for k in varied if isinstance(k, str) and k.startswith("tablet.")}}
    given.update(fam.left_out(given))
    for k in fam.required:
        if k not in given:
            raise DesignError(f"design.tablet.{k}", MISSING, f"family {fam.name!r} needs {fam.needs()}: give it in "
                              "[design.tablet] or vary it (every design would be refused)")


def _check_family_keys(design: dict) -> None:
    """Refuse a key of ``[design.tablet]`` that the named family does not take (every row would fail)."""
    fam = _family_of(design)
    if fam is None:
        return
    for k, v in design["tablet"].items():
        if k not in fam.params and k not in ("family", "name", "a"):
            raise DesignError(f"design.tablet.{k}", v, f"family {fam.name!r} takes {', '.join(fam.params)}")


def _check_fixed_dimensions(design: dict, varied: set[str]) -> None:
    """Refuse a dimension of ``[design.tablet]`` that the sweep does not vary and that no design could
    take, whatever the varied values: not a number, not finite, beyond the size limit, below the
    smallest length, or a negative length (every family's lengths are >= 0); and a smoothing parameter
    ``a`` its family refuses: outside (0, 1] for an industry family, not > 0 for a thesis shape.  Every row
    would fail.  A value that one family
    refuses by its own rules (a concave round's band of 0) is left to the rows: whether it fails can
    depend on the varied values."""
    from tabletcad.pipeline.design import _number

    fam = _family_of(design)
    if fam is None:
        return
    a = design["tablet"].get("a")
    if a is not None and a != "auto" and "tablet.a" not in varied:  # the smoothing parameter, as the family reads it
        from tabletcad.errors import check_positive, check_range
        from tabletcad.families import INDUSTRY_FAMILIES

        x = _number("design.tablet.a", a)
        if fam.name in INDUSTRY_FAMILIES:  # (0, 1] (tabletcad.families.round.smoothing)
            check_range("design.tablet.a", x, 0.0, 1.0, lo_open=True)
        else:  # a thesis shape's patches take any a > 0 (a = 1.5 builds a sphere 5.015 mm across)
            check_positive("design.tablet.a", x)
    for k, v in design["tablet"].items():
        if k in fam.params and f"tablet.{k}" not in varied:
            where = f"design.tablet.{k}"
            x = _number(where, v, fam.params[k])
            if fam.params[k] == "mm" and x < 0.0:  # no family takes it: named with the family's own range
                raise DesignError(where, v, f"{_family_range(fam, k, v)} (a length of {fam.name}; the sweep does not "
                                  "vary it, so every design would be refused)", "mm")


def _check_varied_length(design: dict, key: str, spec: Any) -> None:
    """Refuse a list entry or a range's end of a varied length of the family (``tablet.<param>`` in mm)
    beyond the size limit (``Tolerances.max_length``), where every design reader refuses a length, named
    as the file has it: a range's ``max = 1e300`` had failed its rows one by one, exit 0.  A value that
    only the family refuses (a negative land) is left to the rows, as is every value within the limit.

    Parameters
    ----------
    design : dict
        The sweep's ``[design]`` table.
    key : str
        The varied dotted key.
    spec : list or dict
        Its ``[sweep.vary]`` entry: a list of values or a ``{ min, max, num }`` range (already checked to be
        numbers where the key is a dimension).
    """
    from tabletcad.pipeline.design import _number as _design_number

    fam = _family_of(design)
    name = key.split(".", 1)[1] if key.startswith("tablet.") else None
    if fam is None or fam.params.get(name) != "mm":
        return
    where = f"[sweep.vary] {key!r}"
    given = [(where, v) for v in spec] if isinstance(spec, list) else [(f"{where} {k}", spec[k]) for k in ("min", "max")]
    for at, v in given:  # (a range's inner values lie between its ends)
        _design_number(at, v, "mm", least=False)


def _family_range(fam, key: str, value: float) -> str:
    """The lower bound ``fam`` sets to a length ``key``, from its own refusal of the negative ``value`` (``must be
    > 0``: a diameter of 0 is refused too), its constructor called with that value and its defaults (it checks
    each length before it builds anything; an upper bound, which depends on the other dimensions, is left
    out); ``must be >= 0`` when the family names another parameter first."""
    import re
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fam.func(**{key: value})
    except DesignError as exc:
        bound = re.match(r"must be >=? 0(?![.\d])", exc.allowed) if exc.parameter == key else None
        if bound:
            return bound.group(0)
    except Exception:  # noqa: BLE001 - (a constructor that fails otherwise says nothing of the range)
        pass
    return "must be >= 0"


def _check_fixed_tables(design: dict, axes) -> None:
    """Refuse what a design's ``[report]`` or ``[tooling]`` table says wrong (an unknown key, a solid
    fraction of 1.5) when the sweep varies none of its keys: every row would fail with it.  Each table
    is read as a design reads it (:class:`~tabletcad.pipeline.design.Design`, no geometry); a table
    with a varied key (whose keys may depend on one another) and a tooling table naming font or SVG
    files (which a remote scheduler's workers may hold) are left to the rows."""
    from tabletcad.pipeline.design import Design

    for table in ("report", "tooling"):
        if table not in design or any(a.key.split(".")[0] == table for a in axes):
            continue  # a table the sweep varies: its keys may depend on one another (a standard and its sizes)
        if table == "tooling" and any(isinstance(e, dict) and ("svg" in e or "font" in e)
                                      for e in (design["tooling"].get("emboss") or [] if isinstance(design["tooling"], dict) else [])):
            continue  # files a remote scheduler's workers may hold and this machine not
        try:
            Design.from_dict({"tablet": design["tablet"], table: design[table]})
        except DesignError as exc:
            if exc.parameter.split(".")[0].split("[")[0] == table:
                raise exc.renamed(f"design.{exc.parameter}") from None


def _known_keys(design: dict) -> set[str]:
    """Dotted keys that may be varied: every scalar of the base design, and the family's parameters."""
    keys: set[str] = set()

    def walk(prefix: str, node: Any) -> None:
        if isinstance(node, dict):
            for k, v in node.items():
                walk(f"{prefix}.{k}" if prefix else k, v)
        elif prefix:
            keys.add(prefix)

    walk("", design)
    tab = design.get("tablet", {})
    fam = tab.get("family") if isinstance(tab, dict) else None
    from tabletcad.families import FAMILIES, RENAMED

    fam = RENAMED.get(fam, fam) if isinstance(fam, str) else fam  # each design warns of an old name when built
    if fam in FAMILIES:
        keys |= {f"tablet.{k}" for k in FAMILIES[fam].params} | {"tablet.a", "tablet.name"}
    try:
        from dataclasses import fields

        from tabletcad.pipeline.designreport import ReportOptions

        keys |= {f"report.{f.name}" for f in fields(ReportOptions)}
    except ImportError:  # pragma: no cover
        pass
    return keys


def _axis(key: str, spec: Any, method: str) -> Axis:
    where = f"[sweep.vary] {key!r}"
    if isinstance(spec, list):
        if not spec:
            raise DesignError(where, "[]", "an empty list sweeps nothing; give at least one value")
        for v in spec:
            if isinstance(v, (dict, list)):
                raise DesignError(where, v, "list entries must be numbers, strings or booleans")
        return Axis(key, tuple(spec))
    if not isinstance(spec, dict):
        raise DesignError(where, spec, "must be a list of values or a table { min = ..., max = ..., num = ... }")
    allowed = {"min", "max", "num"} if method == "grid" else {"min", "max"}
    for k in spec:
        if k not in allowed:
            raise DesignError(f"{where} key {k!r}", spec[k], f"a {method} range takes {', '.join(sorted(allowed))}")
    for k in ("min", "max"):
        if k not in spec:
            raise DesignError(f"{where} {k}", MISSING, f"a range needs {', '.join(sorted(allowed))}")
    lo, hi = _number(f"{where} min", spec["min"]), _number(f"{where} max", spec["max"])
    if hi < lo:
        raise DesignError(f"{where} max", hi, f"the range is empty: max must be >= min = {format_bound(lo, upper=False)}")
    if not math.isfinite(hi - lo):  # (-1.7e308 to 1.7e308 gave inf and nan values)
        raise DesignError(f"{where} max", hi, f"the range's width from min = {lo:g} must be a finite number")
    if method == "lhs":
        return Axis(key, (), lo, hi)
    if "num" not in spec:
        raise DesignError(f"{where} num", MISSING, "a grid range needs num (the number of values, >= 1)")
    num = spec["num"]
    if isinstance(num, bool) or not isinstance(num, int) or not 0 < num <= MAX_DESIGNS:
        raise DesignError(f"{where} num", num, f"must be an integer from 1 to {MAX_DESIGNS:,}")
    if num == 1:
        values: tuple[float, ...] = (lo,) if lo == hi else ()
        if not values:
            raise DesignError(f"{where} num", num, f"one value cannot span {lo:g} to {hi:g}; give num >= 2 or min = max")
        return Axis(key, values)
    import numpy as np

    # rounded to 12 significant digits, so that 0.6 to 1.2 in 3 steps gives 0.9, not 0.8999999999999999
    return Axis(key, tuple(float(f"{v:.12g}") for v in np.linspace(lo, hi, num)))


def parse_sweep(data: dict[str, Any], name: str = "sweep") -> SweepSpec:
    """Check a parsed sweep file and return its :class:`SweepSpec` (no design is built)."""
    for k in data:
        if k not in ("design", "sweep"):
            raise DesignError(f"top-level key {k!r}", data[k], "a sweep file has a [design] and a [sweep] table")
    design = data.get("design")
    if not isinstance(design, dict) or not isinstance(design.get("tablet"), dict):
        shown = MISSING if design is None else design  # (a [design] given as "tablet = 3" was "not given")
        raise DesignError("[design]", shown, "a sweep file needs a [design] table with a [design.tablet] table")
    from tabletcad.pipeline.design import TOP_LEVEL_KEYS

    for k in design:
        if k not in TOP_LEVEL_KEYS:
            raise DesignError(f"[design] key {k!r}", design[k], f"allowed keys are {', '.join(TOP_LEVEL_KEYS)}")
    sw = data.get("sweep")
    if not isinstance(sw, dict):
        raise DesignError("[sweep]", MISSING, "a sweep file needs a [sweep] table with [sweep.vary]")
    for k in sw:
        if k not in _SWEEP_KEYS:
            raise DesignError(f"[sweep] key {k!r}", sw[k], f"allowed keys are {', '.join(sorted(_SWEEP_KEYS))}")
    method = sw.get("method", "grid")
    if method not in ("grid", "lhs"):
        raise DesignError("[sweep] method", method, "must be 'grid' or 'lhs'")
    samples = seed = None
    if method == "lhs":
        if "samples" not in sw:
            raise DesignError("[sweep] samples", MISSING, "a Latin hypercube needs samples (an integer >= 1)")
        samples = sw["samples"]
        if isinstance(samples, bool) or not isinstance(samples, int) or not 0 < samples <= MAX_DESIGNS:
            raise DesignError("[sweep] samples", samples, f"must be an integer from 1 to {MAX_DESIGNS:,}")
        if "seed" not in sw:
            raise DesignError("[sweep] seed", MISSING, "samples need a seed (an integer >= 0) so that the sweep can be repeated")
        seed = sw["seed"]
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise DesignError("[sweep] seed", seed, "must be an integer >= 0")
    else:
        for k in ("samples", "seed"):
            if k in sw:
                raise DesignError(f"[sweep] {k}", sw[k], "only a Latin hypercube (method = 'lhs') takes samples and seed")
    outputs = sw.get("outputs", ["report"])
    if isinstance(outputs, str):
        outputs = [outputs]
    if not isinstance(outputs, list) or not outputs:
        raise DesignError("[sweep] outputs", outputs, f"must be a list of {', '.join(OUTPUTS)}")
    for o in outputs:
        if o not in OUTPUTS:
            raise DesignError("[sweep] outputs", o, f"must be one of {', '.join(OUTPUTS)}")
    store = sw.get("store")
    if store is not None and (not isinstance(store, str) or not store.strip()):
        raise DesignError("[sweep] store", store, "must be a folder path or fsspec URL")
    vary = sw.get("vary")
    if not isinstance(vary, dict) or not vary:
        raise DesignError("[sweep.vary]", MISSING if vary is None else vary, "give at least one dotted design key to vary")
    _check_family_keys(design)  # (a misspelt key first: it is why a dimension is missing)
    _check_family(design, set(vary))
    _check_fixed_dimensions(design, set(vary))
    known = _known_keys(design)
    dims = _dimension_keys(design)
    axes = []
    for key, spec in vary.items():
        if key not in known:
            raise DesignError("[sweep.vary] key", key, "must name a value of [design] or a parameter of its family "
                              "(e.g. 'tablet.cup_depth'); known: " + ", ".join(sorted(known)))
        axis = _axis(key, spec, method)
        for v in axis.values if key in dims else ():  # a dimension is a number in every design ("a" failed every row)
            _number(f"[sweep.vary] {key!r}", v)
        _check_varied_length(design, key, spec)
        axes.append(axis)
    if method == "grid" and math.prod(len(a.values) for a in axes) > MAX_DESIGNS:
        raise DesignError("[sweep.vary]", " x ".join(str(len(a.values)) for a in axes),
                          f"must give at most {MAX_DESIGNS:,} designs (the grid's product)")
    _check_fixed_tables(design, axes)
    return SweepSpec(design=design, axes=tuple(axes), method=method, samples=samples, seed=seed,
                     outputs=tuple(dict.fromkeys(["report", *outputs])), store=store, name=name)
