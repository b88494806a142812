"""A tablet family: a named constructor with its parameters and their units.

The catalogue of every family (the thesis's shapes and the industry families)
is the static mapping :data:`tabletcad.families.FAMILIES`.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import inspect
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Iterator, Mapping

from tabletcad.errors import DesignError, is_number

if TYPE_CHECKING:  # pragma: no cover
    from tabletcad.geometry.tablet import Tablet

__all__ = ["Family", "lengths_checked", "lengths_unchecked"]

_UNCHECKED: contextvars.ContextVar[bool] = contextvars.ContextVar("tabletcad_lengths_unchecked", default=False)


@contextlib.contextmanager
def lengths_unchecked() -> Iterator[None]:
    """Inside the block the constructors build a length below ``tol.min_length`` as they did before
    :func:`lengths_checked`: for the searches that follow a dimension down towards 0 and put what they
    find on 0 or the least length themselves (:mod:`tabletcad.families.inverse`, the optimiser's
    evaluations).  Keyed on a context variable: other threads and contexts are checked as usual."""
    token = _UNCHECKED.set(True)
    try:
        yield
    finally:
        _UNCHECKED.reset(token)


def lengths_checked(*, skip: tuple[str, ...] = ()) -> Callable:
    """Make a family's constructor refuse a length between 0 and ``tol.min_length`` (1e-3 mm), or beyond
    ``±tol.max_length`` (1000 mm, the size limit), as a design file does, naming it: each positional-or-keyword parameter but ``skip`` (an angle, the
    outline's points) is a length.  Below that length the constructors had built nonsense or failed
    late (a 1e-300 mm cup depth made a tablet of volume NaN, 5e-324 mm ran for minutes, a 1e-9 mm band
    built and then failed in the CAD stage with "sewn shell has 2 faces", a 1e-300 mm wide caplet
    raised ZeroDivisionError).

    The refusal says whether 0 is allowed, as the constructor answers it: the same call with that
    parameter 0 (any other length below the least one at the least one) builds, or it does not."""

    def wrap(func: Callable) -> Callable:
        sig = inspect.signature(func)
        names = tuple(k for k, p in sig.parameters.items() if p.kind is p.POSITIONAL_OR_KEYWORD and k not in skip)

        def short(bound: inspect.BoundArguments, least: float) -> list[str]:
            return [k for k in names if k in bound.arguments and is_number(bound.arguments[k])
                    and 0.0 < float(bound.arguments[k]) < least]

        @functools.wraps(func)
        def checked(*args: Any, **kwargs: Any):
            if _UNCHECKED.get():
                return func(*args, **kwargs)
            try:
                bound = sig.bind(*args, **kwargs)
            except TypeError:
                return func(*args, **kwargs)  # (Python's own message for a wrong call)
            tol = bound.arguments.get("tol")
            if tol is None:
                tol = sig.parameters["tol"].default if "tol" in sig.parameters else None
            least = float(getattr(tol, "min_length", 1e-3))
            most = float(getattr(tol, "max_length", 1000.0))
            for k in names:  # the size limit a design file keeps (a larger length builds a tablet beyond it)
                x = bound.arguments.get(k)
                if is_number(x) and abs(float(x)) > most:
                    raise DesignError(k, x, f"must be within ±{most:g} mm (size limit, Tolerances.max_length)", "mm")
            bad = short(bound, least)
            if bad:
                k, value = bad[0], bound.arguments[bad[0]]
                probe = sig.bind(*args, **kwargs)
                probe.arguments[k] = 0.0
                for other in bad[1:]:
                    probe.arguments[other] = least
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        func(*probe.args, **probe.kwargs)
                    zero = True
                except Exception:  # (refused, or failing: either way 0 is not what it builds)
                    zero = False
                raise DesignError(k, value, f"must be {'0 or ' if zero else ''}at least {least:g} mm "
                                  "(Tolerances.min_length: a smaller feature is below the tolerance the surface "
                                  "is certified to)", "mm")
            return func(*args, **kwargs)

        return checked

    return wrap


@dataclass(frozen=True, eq=False)
class Family:
    """A named constructor with its parameters, units and defaults.

    A parameter is *optional* when its default switches a feature off (0 mm:
    no land, no bevel depth, no blend, a cup as wide as the outline allows, a
    single-radius cup); every other parameter is a dimension that a design file
    must give (``required``).

    Parameters
    ----------
    name : str
        The name design files use (``[tablet] family``).
    func : callable
        ``func(**params, a=..., tol=...) -> Tablet``.
    params : mapping
        Parameter name -> unit (``"mm"``, ``"deg"``), in the constructor's order.
    alternatives : mapping
        A required parameter -> the optional one that may be given instead (a bevel's width or its
        depth): with only the alternative given, the required one is 0 (:meth:`left_out`).
    """

    name: str
    func: Callable[..., Tablet]
    params: Mapping[str, str]
    doc: str = field(default="", repr=False)
    alternatives: Mapping[str, str] = field(default_factory=dict, repr=False)

    @classmethod
    def of(cls, func: Callable[..., Tablet], units: Mapping[str, str] | None = None, name: str | None = None,
           alternatives: Mapping[str, str] | None = None) -> Family:
        """The family of a constructor: its positional-or-keyword parameters, in mm unless ``units`` says."""
        units = units or {}
        sig = inspect.signature(func)
        params = {k: units.get(k, "mm") for k, p in sig.parameters.items() if p.kind is p.POSITIONAL_OR_KEYWORD}
        return cls(name or func.__name__, func, params, (func.__doc__ or "").strip().splitlines()[0],
                   dict(alternatives or {}))

    def left_out(self, given: Mapping[str, Any]) -> dict[str, float]:
        """The required parameters not in ``given`` (name -> value, None for a value still to be found)
        whose alternative is, other than 0, each 0 (``{"bevel_width": 0.0}`` for a ffbe given its
        ``bevel_depth``): what a design adds before it builds."""
        return {k: 0.0 for k, alt in self.alternatives.items() if k not in given and alt in given and given[alt] != 0.0}

    def needs(self, besides: str | None = None) -> str:
        """The required parameters (but ``besides``) as a refusal names them (``bevel_width (or bevel_depth)``)."""
        return ", ".join(f"{k} (or {self.alternatives[k]})" if k in self.alternatives else k
                         for k in self.required if k != besides)

    @property
    def defaults(self) -> dict[str, Any]:
        """Each parameter's default value (mm or degrees)."""
        sig = inspect.signature(self.func)
        return {k: sig.parameters[k].default for k in self.params}

    @property
    def required(self) -> tuple[str, ...]:
        """Parameters a design must give (those whose default is not 0, i.e. real dimensions)."""
        return tuple(k for k, d in self.defaults.items() if d != 0.0)

    @property
    def description(self) -> str:
        """The first paragraph of the constructor's docstring on one line (whole sentences)."""
        text = (self.func.__doc__ or self.doc or "").strip().split("\n\n")[0]
        return " ".join(text.replace("``", "").split())

    def build(self, **kw: Any) -> Tablet:
        """The tablet of these dimensions (unknown keywords are a :class:`DesignError`)."""
        unknown = set(kw) - set(self.params) - {"a"}
        if unknown:
            k = sorted(unknown)[0]
            raise DesignError(f"tablet.{k}", kw[k], f"family {self.name!r} takes {', '.join(self.params)}")
        return self.func(**kw)
