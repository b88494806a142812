"""Every picture tabletcad saves with matplotlib goes through :func:`save_figure`: one set of bytes per figure.

matplotlib names an SVG's clip paths and other elements by hashes salted with a random UUID
(``svg.hashsalt``), and dates an SVG (``dc:date``) and a PDF (``CreationDate``) with the local time of
writing.  Here the salt is fixed and the date is :func:`tabletcad.io.timestamp.stamp_time`'s (UTC;
``SOURCE_DATE_EPOCH`` when the environment sets it), so that two runs of a command give the same file.
A PNG carries no date (only matplotlib's ``Software`` text).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

from tabletcad.io.atomic import atomic_path
from tabletcad.io.timestamp import stamp_time

__all__ = ["SVG_SALT", "save_figure", "figure_metadata"]

#: the salt of the SVG element ids' hashes: any fixed text (matplotlib's default is a random UUID per save)
SVG_SALT = "tabletcad"


def figure_metadata(fmt: str, metadata: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """matplotlib's ``metadata`` for a file of format ``fmt``, dated by :func:`stamp_time` unless ``metadata``
    dates it.

    Parameters
    ----------
    fmt : str
        matplotlib's format name (``"png"``, ``"svg"``, ``"pdf"``, ...), lower case.
    metadata : mapping, optional
        The caller's entries (``{"Software": ...}``), which are kept.

    Returns
    -------
    dict
        ``metadata`` with ``Date`` (SVG, ISO 8601 with its UTC offset) or ``CreationDate`` (PDF) added.
    """
    out = dict(metadata or {})
    if fmt == "svg":
        out.setdefault("Date", stamp_time().isoformat())
    elif fmt == "pdf":
        out.setdefault("CreationDate", stamp_time())
    return out


def save_figure(fig: Any, target: str | os.PathLike[str] | IO[bytes], *, fmt: str | None = None,
                metadata: Mapping[str, Any] | None = None, rc: Mapping[str, Any] | None = None,
                **kwargs: Any) -> Path | None:
    """Save the matplotlib figure ``fig`` reproducibly: to a file atomically, or into an open binary stream.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, with a canvas.
    target : path or binary file object
        A path is written atomically (:func:`tabletcad.io.atomic_path`); a stream (``io.BytesIO``) is written to.
    fmt : str, optional
        matplotlib's format; default: the path's suffix, else ``"png"``.
    metadata : mapping, optional
        matplotlib ``metadata`` entries; the date is :func:`stamp_time`'s unless given here.
    rc : mapping, optional
        Further rcParams for this save (``{"svg.fonttype": "none"}``); ``svg.hashsalt`` is :data:`SVG_SALT`
        unless given here.
    **kwargs
        Passed to :meth:`~matplotlib.figure.Figure.savefig` (``dpi``, ``pil_kwargs``).

    Returns
    -------
    Path or None
        The path written, or None for a stream.
    """
    import matplotlib

    is_path = isinstance(target, (str, os.PathLike))
    if fmt is None:
        fmt = (Path(target).suffix.lstrip(".") if is_path else "") or "png"
    fmt = fmt.lower()
    params = {"svg.hashsalt": SVG_SALT, **(rc or {})}
    meta = figure_metadata(fmt, metadata)
    with matplotlib.rc_context(params):
        if not is_path:
            fig.savefig(target, format=fmt, metadata=meta, **kwargs)
            return None
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format=fmt, metadata=meta, **kwargs)
    return Path(target)
