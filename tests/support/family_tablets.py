"""The family samples' tablets and their B-reps, built once per test session: the tooling tests of
several files (tests/test_tooling_parts.py, tests/test_tooling_taper_gap.py) build tooling for every
family sample, each from the same tablet and solid (its B-rep fit takes up to 2 s)."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path


@lru_cache(maxsize=None)
def family_tablet(path: Path):
    """``(tablet, shape)`` of the family design file ``path``: the tablet and the B-spline solid that
    :func:`~tabletcad.tooling.outline.tablet_frame` builds for its tooling (read-only: share, do not change)."""
    from tabletcad.cli.report import load_family_design
    from tabletcad.tooling.outline import tablet_frame

    tablet, _ = load_family_design(Path(path))
    return tablet, tablet_frame(tablet, None).shape
