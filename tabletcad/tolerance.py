"""The one tolerance object of tabletcad.

Every numerical threshold the package uses lives here, documented, instead
of being scattered as literals.  Lengths are in millimetres.  Change a value
with :func:`dataclasses.replace` and pass the result where a function takes
``tol=``; :data:`DEFAULT` is used otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tolerances", "DEFAULT"]


@dataclass(frozen=True)
class Tolerances:
    """Numerical tolerances (lengths in mm, angles in degrees).

    Attributes
    ----------
    interpolation : float
        Largest allowed distance (mm) between a PDE patch and its boundary
        curves at the curve parameters; the remainder term guarantees it.
    fourier : float
        A curve is represented by ``N`` Fourier modes when the truncated series
        is within this distance (mm) of the curve everywhere (sampled densely).
    stray : float
        Largest allowed distance (mm) that the modes a curve needs only below
        ``fourier`` (plus the remainder term) may move the surface between the
        curves.  A patch exceeding it is refused: its shape would be driven by
        amplified high-frequency content instead of by the design.
    max_amplification : float
        Largest factor by which a mode present in the design may be amplified
        between interior curves (the maximum of its Lebesgue function); beyond
        it the surface between the curves is set by the amplification rather
        than by the design, and the patch is refused.
    max_modes : int
        Upper bound on the number of Fourier modes ``N`` carried analytically;
        content above it goes into the remainder term.
    samples : int
        Least number of samples per curve for the FFT of a curve that is not band-limited
        (rounded up to a multiple of 240: :func:`~tabletcad.geometry.curves.fourier_samples`).
    quad_u : int
        Gauss-Legendre points in ``u`` per patch for area/volume quadrature.
    quad_v : int
        Trapezoidal points in ``v`` (periodic, spectrally accurate).
    seam_gap : float
        Seam gap (mm) above which two patches are reported as not meeting.
    seam_angle_deg : float
        Normal angle (deg) below which a seam counts as tangent-continuous (G1).
    fold : float
        Depth (mm) to which a patch's solid map may fold back on itself before
        the patch is refused (see :meth:`PDEPatch.fold_depth`), or
        ``fold_fraction`` of its reach where that is more (:meth:`PDEPatch.fold_limit`);
        the thesis's domes fold by ~1 µm at their poles.  A swept family's patches
        and the radius check (a surface passing through its spine) use ``fold`` alone.
    fold_fraction : float
        The fold limit as a fraction of the patch's reach (its largest distance
        from its spine): the thesis's domes fold in proportion to their size (the
        sphere, and an oblong whose domes are half its diameter high, by 3.3e-4 of
        their radius; the prolate spheroid by 6.6e-4), so a shape taken at 5 mm
        is taken at 500 mm.  To tighten the limit, lower both.
    fit : float
        Largest deviation (mm) of a B-spline face from its PDE patch (CAD layer).
    nominal : float
        Largest deviation (mm) of a PDE surface from a family's exact nominal.
    max_length : float
        Size limit (mm) of design input: every length, coordinate and overall
        dimension read from a design file or the command line lies within
        ``[-max_length, max_length]`` (1 m; the largest pharmaceutical and
        veterinary boluses are a few cm).  Beyond it the numbers stop being a
        tablet and rounding errors exceed the nanometre tolerances above.
    min_length : float
        Smallest length (mm) other than 0 that a design may give (a band, land, cup
        depth, diameter...): the tolerance ``nominal`` the surfaces are certified to; a
        smaller feature would be lost in it (and closes up when the faces are sewn).
    memory_fraction : float
        Share of the memory the system reports available (Linux ``MemAvailable``)
        that one command may plan to use; a mesh estimated larger is refused
        before it is allocated.
    mesh_bytes_per_node : int
        Peak memory (bytes) of a mesh per node, for that estimate (measured on 2026-12-06: 151-155
        bytes per node from ``tabletcad mesh samples/spherical.toml`` with two layers at 1.3e6-2.9e6
        nodes, 253-281 for hexahedral meshes of 10 and 40 layers at 1.8e6-3.5e6 nodes).
    offset_regularity : float
        Relative margin kept below a smooth (spline) outline's smallest radius of
        curvature by the inward offsets of a cup: at exactly that radius the offset
        stands still at one point (a singular rim that B-spline faces fold over).
    mesh_deflection : float
        Linear deflection (mm) of the triangle meshes of solids: the largest distance
        between a triangle and its face (STL, GLB, the mesh checks, the tooling's
        manifold3d cross-checks).
    mesh_angle : float
        Angular deflection (rad) of those meshes: the largest angle between
        neighbouring triangles' normals along a face.
    brep_agreement : float
        Largest relative difference allowed between a B-rep solid's volume or area
        (OCC mass properties) and the core's quadrature of the same tablet.
    revolution : float
        Largest Fourier coefficient (mm) that may break a patch's symmetry about the z
        axis for the patch to be treated as an exact surface of revolution (its
        extents, plan area and CAD faces then come from its profile; see
        :mod:`tabletcad.geometry.revolution`).  Round-off of exact circles is ~1e-15 mm.
    mesh_volume : float
        Relative difference between a hexahedral mesh's volume and the solid's exact
        volume above which ``tabletcad mesh`` warns (straight-edged cells cut the
        curved faces: 13 % low for the flat-faced round at 8 × 8 × 8 nodes).
    """

    interpolation: float = 1e-9
    fourier: float = 1e-9
    stray: float = 1e-3
    max_amplification: float = 1e3
    max_modes: int = 48
    samples: int = 512
    quad_u: int = 48
    quad_v: int = 256
    seam_gap: float = 1e-7
    seam_angle_deg: float = 0.01
    fold: float = 5e-3
    fold_fraction: float = 2e-3
    fit: float = 1e-4
    nominal: float = 1e-3
    max_length: float = 1000.0
    min_length: float = 1e-3
    memory_fraction: float = 0.5
    mesh_bytes_per_node: int = 300
    offset_regularity: float = 1e-2
    mesh_deflection: float = 0.005
    mesh_angle: float = 0.2
    brep_agreement: float = 1e-6
    mesh_volume: float = 1e-2
    revolution: float = 1e-11


DEFAULT = Tolerances()

#: the largest true density taken, mg/mm³ (= g/cm³): above every solid's (osmium 22.6); a density in
#: kg/m³ (lactose 1540) is 1000 times too large and refused (press data, design reports, inverse design)
MAX_TRUE_DENSITY_MG_MM3 = 25.0
#: the least true density taken, mg/mm³: below every pharmaceutical solid's (waxes, about 0.9); one in
#: g/mm³ (lactose 0.00154) is 1000 times too small and refused (it had given a weight 1000 times low)
MIN_TRUE_DENSITY_MG_MM3 = 0.1

#: The least force (N) an FE load (diametral test, punch) takes: below it the stresses underflow (a
#: force of 1e-320 N read a centre stress of -0 MPa, and 1e-200 kN on a punch left no stress to divide
#: the yield stress by).
#: The analyses are linear, so their figures per newton do not depend on it.
MIN_FORCE_N = 1e-6
#: The largest yield stress (MPa) a punch rating takes: no tool steel reaches 4 GPa, and a yield stress
#: typed in pascals (1.45e9) had rated a punch at 2508 kN.
MAX_YIELD_MPA = 10000.0
#: The smallest yield stress (MPa) a punch rating takes: punches are tool steels (the S7 tempers of
#: tabletcad/data/tool_steels.toml yield at 1380-1585 MPa, D2 and M2 higher) and even annealed mild
#: steel yields near 200 MPa, so 100 MPa is below any steel a punch is made of.  A yield stress typed in
#: GPa (1.45 for S7's 1450 MPa) had been accepted, rating the punch a thousand times too weak.
MIN_YIELD_MPA = 100.0
#: The range (MPa) of an allowed punch-tip pressure (a tip-force rating ``F = p x tip area``): below the
#: yield of the steels punches are made of, and from 10 MPa, so that one typed in GPa (0.3 for 300 MPa)
#: is refused rather than rating the tips a thousand times too weak (it had been taken, as had 1e9 MPa).
MIN_TIP_PRESSURE_MPA = 10.0
#: The smallest Young's modulus (MPa) of a punch's buckling check: punches are tool steels (190-215 GPa)
#: or carbide (about 600 GPa), and aluminium's 70 GPa is already no punch's; one typed in GPa (210)
#: had been taken, rating the tips' buckling a thousand times too low.
MIN_PUNCH_MODULUS_MPA = 5.0e4
#: The largest effective-length factor ``K`` of the punch's buckling check (a column fixed at one end and
#: free at the other has 2; 1e9 had rated a punch at 1e-14 kN).
MAX_EFFECTIVE_LENGTH_FACTOR = 10.0
#: The largest tensile strength (MPa) a breaking-force prediction or a design's ``[report]`` takes:
#: pharmaceutical compacts break at 0.1-10 MPa, and one typed in pascals (2e6) had been taken.
MAX_TENSILE_STRENGTH_MPA = 1000.0
#: The largest machine compliance (mm/N) a press record's correction takes: press frames and punches
#: deflect about 2e-5 mm/N (the thesis's Appendix B); 1e-3 is a millimetre per kilonewton.  A
#: calibration typed in kN (0.02 mm/N) had been taken, and 1e300 gave a Heckel slope of -2.6e-303.
MAX_COMPLIANCE_MM_PER_N = 1e-3
#: The largest Young's modulus (MPa) an analysis takes: above every solid's (diamond 1.2e6); E = 1e300
#: had given shell displacements of 1e-297 mm and a Heckel Py of inf (love).
MAX_MODULUS_MPA = 1e7
#: The largest pressure (MPa) a mechanics model takes: a hundred times any tool steel's strength; a platen
#: pressure of 1e300 had given a shell displacement of -7.5e297 mm, exit 0.
MAX_PRESSURE_MPA = 1e5
