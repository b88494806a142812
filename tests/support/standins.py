"""Analytic stand-in surface patches (numpy only, no CAD kernel).

Each factory returns an ordered chain of :class:`AnalyticPatch` objects with
the interface of the PDE patches (``evaluate(u, v)`` -> ``(..., 3)``,
``u`` in [0, 1], ``v`` periodic in [0, 2 pi)); patch ``j``'s ``u=1`` curve is
patch ``j+1``'s ``u=0`` curve, and the closed-form volume and area are known.
The CAD tests fit and sew them: geometry with closed-form volume and area, independent of the PDE core.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["AnalyticPatch", "StandIn", "sphere", "cylinder", "ring"]


@dataclass(frozen=True)
class AnalyticPatch:
    name: str
    fn: Callable[[np.ndarray, np.ndarray], np.ndarray]

    def evaluate(self, u, v) -> np.ndarray:
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        return self.fn(u, v)

    def __call__(self, u, v) -> np.ndarray:
        return self.evaluate(u, v)


@dataclass(frozen=True)
class StandIn:
    """A closed chain of patches with its exact volume (mm^3), area (mm^2) and genus."""

    name: str
    patches: tuple[AnalyticPatch, ...]
    volume: float
    area: float
    genus: int


def _xyz(x, y, z) -> np.ndarray:
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


def sphere(radius: float = 2.5, centre=(0.0, 0.0, 0.0)) -> StandIn:
    """Two hemispheres; ``u`` is the polar angle / (pi/2) (north pole -> equator -> south pole)."""
    r, (cx, cy, cz) = float(radius), centre

    def hemi(offset):
        def f(u, v):
            th = 0.5 * math.pi * (u + offset)
            return _xyz(cx + r * np.sin(th) * np.cos(v), cy + r * np.sin(th) * np.sin(v), cz + r * np.cos(th))

        return f

    return StandIn(
        f"sphere r={r:g}",
        (AnalyticPatch("north hemisphere", hemi(0.0)), AnalyticPatch("south hemisphere", hemi(1.0))),
        4.0 / 3.0 * math.pi * r**3,
        4.0 * math.pi * r**2,
        0,
    )


def cylinder(radius: float = 2.5, height: float = 3.0) -> StandIn:
    """Bottom disc (centre -> rim), side band (z = 0 -> h), top disc (rim -> centre)."""
    r, h = float(radius), float(height)
    patches = (
        AnalyticPatch("bottom disc", lambda u, v: _xyz(r * u * np.cos(v), r * u * np.sin(v), 0.0 * u)),
        AnalyticPatch("side band", lambda u, v: _xyz(r * np.cos(v) + 0 * u, r * np.sin(v) + 0 * u, h * u)),
        AnalyticPatch("top disc", lambda u, v: _xyz(r * (1 - u) * np.cos(v), r * (1 - u) * np.sin(v), h + 0 * u)),
    )
    return StandIn(f"cylinder r={r:g} h={h:g}", patches, math.pi * r * r * h, 2 * math.pi * r * (r + h), 0)


def ring(inner_radius: float = 1.5, outer_radius: float = 3.0, height: float = 2.0) -> StandIn:
    """A genus-1 tube: bottom annulus, outer wall, top annulus, inner wall (a closed chain)."""
    a, b, h = float(inner_radius), float(outer_radius), float(height)

    def annulus(r0, r1, z):
        return lambda u, v: _xyz((r0 + (r1 - r0) * u) * np.cos(v), (r0 + (r1 - r0) * u) * np.sin(v), z + 0 * u)

    def wall(r, z0, z1):
        return lambda u, v: _xyz(r * np.cos(v) + 0 * u, r * np.sin(v) + 0 * u, z0 + (z1 - z0) * u)

    patches = (
        AnalyticPatch("bottom annulus", annulus(a, b, 0.0)),
        AnalyticPatch("outer wall", wall(b, 0.0, h)),
        AnalyticPatch("top annulus", annulus(b, a, h)),
        AnalyticPatch("inner wall", wall(a, h, 0.0)),
    )
    return StandIn(
        f"ring a={a:g} b={b:g} h={h:g}",
        patches,
        math.pi * (b * b - a * a) * h,
        2 * math.pi * (b * b - a * a) + 2 * math.pi * (a + b) * h,
        1,
    )
