"""Breaking force of any tablet shape from a tensile strength: an elastic first-crack estimate.

The diametral test of a tablet is linear elastic up to the first crack, and
its stresses scale with the force.  With ``σ_max/P`` the largest tensile
stress per newton of the shape (FE, :func:`tabletcad.fe.diametral.diametral`:
the stress averaged over a ball of the strip width's radius, on the loaded
diametral plane away from the platens; mesh-independent), the force at which that stress reaches the
material's tensile strength ``σ_t`` is

    F = σ_t / (σ_max / P).

The tensile strength is given directly or obtained from a breaking force
``F_ref`` measured on a flat-faced round reference compact (diameter ``D_ref``,
thickness ``t_ref``) of the same material and solid fraction, through the same
FE criterion on that reference: ``σ_t = F_ref · σ_max,ref / P``.  (On a thin
flat disc this is ``2F/(πDt)``, thesis eq 2.4, within the Hondros factor.)

The estimate is an *elastic first-crack* force: it assumes brittle fracture
when the largest (averaged) principal stress reaches ``σ_t`` (Rankine), ignores plastic
flattening at the platens and crack growth after initiation, and assumes the
tensile strength does not depend on the shape (same solid fraction).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from tabletcad.errors import MISSING, DesignError, check_range, format_bound
from tabletcad.tolerance import MAX_TENSILE_STRENGTH_MPA
from tabletcad.tolerance import DEFAULT
from tabletcad.fe.diametral import DiametralResult, diametral

__all__ = ["StrengthInputs", "StrengthPrediction", "predict_breaking_force", "reference_tensile_strength",
           "STRENGTH_KEYS"]

#: ``[report]`` keys read by the prediction (and their units).
STRENGTH_KEYS = {
    "tensile_strength_MPa": "MPa",
    "reference_breaking_force_N": "N",
    "reference_diameter_mm": "mm",
    "reference_thickness_mm": "mm",
}
#: the reference test's keys, in the order a refusal names the first missing or given one
REFERENCE_KEYS = ("reference_breaking_force_N", "reference_diameter_mm", "reference_thickness_mm")


@dataclass(frozen=True)
class StrengthInputs:
    """Either a tensile strength (MPa) or a flat-faced round reference test (N, mm, mm)."""

    tensile_strength_MPa: float | None = None
    reference_breaking_force_N: float | None = None
    reference_diameter_mm: float | None = None
    reference_thickness_mm: float | None = None

    def __post_init__(self) -> None:
        for k, unit in STRENGTH_KEYS.items():
            v = getattr(self, k)
            if v is not None:  # lengths as a design's (Tolerances: 0.001 mm to 1 m), a force <= 1e9 N, a strength
                lo, hi = ((DEFAULT.min_length, DEFAULT.max_length) if unit == "mm" else  # <= 1000 MPa
                          (0.0, MAX_TENSILE_STRENGTH_MPA) if unit == "MPa" else (0.0, 1e9))
                check_range(f"[report] {k}", v, lo, hi, unit, lo_open=unit != "mm")
        ref = [self.reference_breaking_force_N, self.reference_diameter_mm, self.reference_thickness_mm]
        given = sum(v is not None for v in ref)
        if self.tensile_strength_MPa is None and 0 < given < 3:  # name the one the reference test lacks
            lacking = next(k for k, v in zip(REFERENCE_KEYS, ref) if v is None)
            raise DesignError(f"[report] {lacking}", MISSING, "the reference test needs "
                              f"{', '.join(REFERENCE_KEYS)} (or give tensile_strength_MPa instead)")
        if self.tensile_strength_MPa is None and given != 3:
            raise DesignError("[report] tensile_strength_MPa", MISSING,
                              "give it, or all of reference_breaking_force_N, reference_diameter_mm, "
                              "reference_thickness_mm")
        if self.tensile_strength_MPa is not None and given:  # named by the first reference input given
            k, v = next((k, v) for k, v in zip(REFERENCE_KEYS, ref) if v is not None)
            raise DesignError(f"[report] {k}", v, "give either tensile_strength_MPa or the reference test, not both",
                              STRENGTH_KEYS[k])
        if given == 3 and self.reference_thickness_mm > self.reference_diameter_mm:
            raise DesignError("[report] reference_thickness_mm", self.reference_thickness_mm,
                              f"must be <= reference_diameter_mm ({format_bound(self.reference_diameter_mm, upper=True)} mm)", "mm")

    @classmethod
    def from_table(cls, table: dict[str, Any] | None, **override: float | None) -> "StrengthInputs":
        """From a design file's ``[report]`` table (other keys ignored), command-line values first."""
        vals = {k: (table or {}).get(k) for k in STRENGTH_KEYS}
        vals.update({k: v for k, v in override.items() if v is not None})
        for k, v in vals.items():
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
                raise DesignError(f"[report] {k}", v, "must be a number", STRENGTH_KEYS[k])
        return cls(**{k: None if v is None else float(v) for k, v in vals.items()})


@dataclass(frozen=True, eq=False)
class StrengthPrediction:
    """Predicted breaking force (N) of a shape; an elastic first-crack estimate."""

    tensile_strength_MPa: float
    tensile_strength_basis: str
    breaking_force_N: float
    breaking_force_centre_N: float
    max_tensile_per_N: float
    centre_tensile_per_N: float
    result: DiametralResult
    reference: DiametralResult | None = None

    def to_dict(self) -> dict[str, Any]:
        r = self.result
        return {
            "estimate": "elastic first-crack (largest principal stress reaches the tensile strength)",
            "tensile_strength_MPa": self.tensile_strength_MPa,
            "tensile_strength_basis": self.tensile_strength_basis,
            "breaking_force_N": self.breaking_force_N,
            "breaking_force_centre_N": self.breaking_force_centre_N,
            "max_tensile_stress_per_N_per_mm2": self.max_tensile_per_N,
            "centre_tensile_stress_per_N_per_mm2": self.centre_tensile_per_N,
            "first_crack_location_mm": list(r.max_tensile_location_mm),
            "direction": r.direction,
            "strip_width_mm": r.strip_width_mm,
            "shape_factor": r.shape_factor,
            "discretisation_error_relative": r.to_dict()["discretisation_error_relative"],
            "reference_shape_factor": None if self.reference is None else self.reference.shape_factor,
        }


def reference_tensile_strength(inputs: StrengthInputs, sizes: Callable[[Any, str], dict] | None = None,
                               **fe: Any) -> tuple[float, DiametralResult]:
    """Tensile strength (MPa) from the reference test, with the FE result of the reference disc;
    ``sizes(disc, "x")`` gives the disc's own mesh sizes (the coarse mesh's), else ``fe``'s or the default."""
    from tabletcad.families import flat_face_round

    D, t = inputs.reference_diameter_mm, inputs.reference_thickness_mm
    ref = flat_face_round(diameter=D, thickness=t)
    given = {k for k, v in fe.items() if v is not None}  # sizes the caller chose: refusals of them stand
    if sizes is not None:
        fe = {**fe, **sizes(ref, "x")}
    try:
        r = diametral(ref, 1.0, "x", **fe)
    except DesignError as exc:  # a size the disc's own dimensions chose: named by the reference thickness
        if exc.parameter in given:
            raise
        what = exc.parameter.replace("_", " ")
        if exc.value is MISSING:  # a size left to its default: the refusal says which default
            detail = f"its {what}'s {exc.allowed.removeprefix('its ')}"
        else:
            value = f"{exc.value:.4g}" if isinstance(exc.value, float) else exc.value
            detail = f"its {what} {value} {exc.unit} {exc.allowed}"
        raise DesignError("[report] reference_thickness_mm", t, f"makes a {D:g} x {t:g} mm reference disc that the "
                          f"FE cannot mesh: {detail}", "mm") from None
    if not r.max_tensile_stress_MPa > 0.0:  # a disc too thin for its mesh finds no tension: no strength from it
        raise DesignError("[report] reference_thickness_mm", t, f"makes a {D:g} x {t:g} mm reference disc in which "
                          "the FE mesh finds no tensile stress: give a thicker reference", "mm")
    return inputs.reference_breaking_force_N * r.max_tensile_stress_MPa, r


def predict_breaking_force(tablet: Any, inputs: StrengthInputs, direction: str = "width", *, solid: Any = None,
                           sizes: Callable[[Any, str], dict] | None = None, **fe: Any) -> StrengthPrediction:
    """Breaking force (N) of ``tablet`` loaded across ``direction``; ``fe`` goes to :func:`diametral`
    (for the tablet and the reference compact), ``solid`` (the tablet's B-rep, e.g. the scored one)
    to the tablet's alone; ``sizes(body, direction)`` gives each body its own mesh sizes (the coarse
    mesh's: a thin reference disc is not meshed at the tablet's sizes)."""
    ref = None
    if inputs.tensile_strength_MPa is not None:
        st, basis = inputs.tensile_strength_MPa, "given"
    else:
        st, ref = reference_tensile_strength(inputs, sizes, **fe)
        basis = (f"FE on a {inputs.reference_diameter_mm:g} x {inputs.reference_thickness_mm:g} mm flat-faced "
                 f"round reference broken at {inputs.reference_breaking_force_N:g} N")
    r = diametral(tablet, 1.0, direction, solid=solid, **{**fe, **(sizes(tablet, direction) if sizes else {})})
    if r.max_tensile_stress_MPa <= 0 or r.centre_tensile_stress_MPa <= 0:
        raise DesignError("direction", direction, "loads this shape without tension at its centre; choose another")
    return StrengthPrediction(
        tensile_strength_MPa=st, tensile_strength_basis=basis,
        breaking_force_N=st / r.max_tensile_stress_MPa, breaking_force_centre_N=st / r.centre_tensile_stress_MPa,
        max_tensile_per_N=r.max_tensile_stress_MPa, centre_tensile_per_N=r.centre_tensile_stress_MPa,
        result=r, reference=ref)
