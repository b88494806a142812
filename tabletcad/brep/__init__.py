"""Kernel-neutral B-rep data: the tablet's faces as B-spline surfaces (numpy only).

:mod:`.knots` (knot vectors and basis functions), :mod:`.surface` (the
:class:`~tabletcad.brep.surface.BSplineSurfaceData` that OCP and FreeCAD both
build from), :mod:`.fit` (the interpolation fit of a surface function within a
tolerance), :mod:`.surfaces` (a tablet's faces as surface functions, ready for
the fit) and :mod:`.slit` (faces cut where a boundary row stands still).
Nothing here imports a CAD kernel: :mod:`tabletcad.cad` turns this data into
OpenCascade faces, the FreeCAD workbench into ``Part`` faces.
"""
