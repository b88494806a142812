"""Finite-element stresses on the real shape of a tablet or a punch tip.

One module per concept:

* :mod:`tabletcad.fe.mesh` -- tetrahedral meshes of B-rep solids (gmsh's own
  OpenCascade import, size fields near loaded strips), as plain arrays;
* :mod:`tabletcad.fe.elasticity` -- linear isotropic elasticity with quadratic
  tetrahedra (scikit-fem ``ElementTetP2``): assembly, minimal supports for
  self-equilibrated loads, stress recovery, principal and von Mises stresses;
* :mod:`tabletcad.fe.diametral` -- the diametral compression (breaking-force)
  test of any tablet, and the Hondros closed form it is checked against;
* :mod:`tabletcad.fe.prediction` -- breaking force of any shape from a
  tensile strength or a reference test (elastic first-crack estimate);
* :mod:`tabletcad.fe.punch` -- punch-tip stress and force rating;
* :mod:`tabletcad.fe.objective` -- the prediction on a coarse mesh, the figure an optimisation
  evaluates (:mod:`tabletcad.optimise.strength` makes it an objective or constraint);
* :mod:`tabletcad.fe.output` -- ``stress.vtu`` and the central-section picture.

Units: mm, N, MPa.  This package needs the ``fe`` extra (scikit-fem, gmsh) and
the CAD layer (the solids); the numerical core never imports it.
"""
