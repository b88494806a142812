"""The pipeline: from a design file to every output of a build.

:mod:`.design` reads and writes design files (the :class:`~tabletcad.pipeline.design.Design`
value), :mod:`.designreport` and :mod:`.report` make the design and geometry
reports, :mod:`.plot` the pictures, :mod:`.build` runs the build's steps (report,
CAD, tooling, picture) into one folder, and :mod:`.model` is the scripting facade
(``tabletcad.make``, ``tabletcad.load``, ``tabletcad.show``).
"""
