"""Tablet compression tooling from the tablet's B-rep (needs the CAD layer: OCP, build123d, manifold3d).

============  ===================================================================
module        concept
============  ===================================================================
spec          the ``[tooling]`` table: clearance, tip length, die, taper, gap,
              ``[[tooling.score]]``, ``[[tooling.emboss]]``, ``[tooling.punch]``,
              ``[tooling.drawing]``
standards     TSM/EU B/D body dimensions from ``data/tooling_standards.toml``
              (each with its source) and the user's ``[tooling.punch]``
outline       the tablet's band, plan outline (OCC wire) and heights
booleans      exact OCC Booleans, each cross-checked with manifold3d
scores        bisect/quadrisect grooves (V, U, pressure-sensitive; cut-through; short)
split         parts and break surface of the tablet split along its scores
emboss        embossed/debossed text (DejaVu/TTF), outlines or SVG logos, stroke
              angle, legibility numbers
punch         upper/lower punch tips (cup faces, land, working-length datum)
punch_body    complete punches: tip relief, revolved barrel/neck/head, key
die           die with a bore following the outline (taper, TSM sizes)
toolset       :func:`make_tooling`: all of the above and the report section
interference  overlap and gap at the closed position (OCC + manifold3d)
assembly      ``assembly.step`` (named, coloured XCAF parts) and one STEP per part
drawing       plan/front/side views by HLR with toleranced dimensions, title
              block; punches-and-die sheet (SVG, PDF, DXF)
rating        tip-force rating (projected-area pressure rule), tip buckling
batch         :func:`tooling_batch`: many sizes in one call
stage         the ``tabletcad build`` stage (designs with ``[tooling]``)
============  ===================================================================
"""

from __future__ import annotations

from tabletcad.tooling.spec import EmbossSpec, ScoreSpec, ToolingSpec, parse_tooling

__all__ = ["ToolingSpec", "ScoreSpec", "EmbossSpec", "parse_tooling", "make_tooling", "tooling_batch", "tooling_for",
           "write_tooling"]


def __getattr__(name):  # lazy: importing the package does not load OCP
    if name == "make_tooling":
        from tabletcad.tooling.toolset import make_tooling

        return make_tooling
    if name in ("tooling_batch", "tooling_for"):
        from tabletcad.tooling import batch

        return getattr(batch, name)
    if name == "write_tooling":
        from tabletcad.tooling.stage import write_tooling

        return write_tooling
    raise AttributeError(name)
