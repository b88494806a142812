"""Warning classes of the mechanics package.

Every caveat the mechanics code raises is a subclass of :class:`MechanicsWarning`
(itself a :class:`UserWarning`), so a caller can silence or escalate them as a
group with :func:`warnings.filterwarnings`.
"""

from __future__ import annotations

import warnings

__all__ = [
    "DataWarning",
    "FitQualityWarning",
    "MechanicsWarning",
    "ValidityWarning",
    "warn",
]


class MechanicsWarning(UserWarning):
    """Base class of every warning issued by :mod:`tabletcad.mechanics`."""


class DataWarning(MechanicsWarning):
    """Press data were repaired (rows dropped) or look suspicious."""


class FitQualityWarning(MechanicsWarning):
    """A fit is poorly linear or gives physically implausible parameters."""


class ValidityWarning(MechanicsWarning):
    """A formula is used outside the range of geometry or load it was derived for."""


def warn(category: type[MechanicsWarning], message: str, stacklevel: int = 3) -> None:
    """Issue ``message`` as ``category`` pointing at the caller's caller."""
    warnings.warn(message, category, stacklevel=stacklevel)
