"""A tablet family: a named constructor with its parameters and their units.

The catalogue of every family (the thesis's shapes and the industry families)
is the static mapping :data:`tabletcad.families.FAMILIES`.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Mapping

from tabletcad.errors import DesignError

if TYPE_CHECKING:  # pragma: no cover
    from tabletcad.geometry.tablet import Tablet

__all__ = ["Family"]


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
