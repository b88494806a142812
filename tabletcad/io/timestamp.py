"""The date and time that tabletcad's files carry, and identifiers derived from their content.

A STEP header, a DXF header, an SVG's and a PDF's metadata and a 3MF's zip entries each hold a
date.  They all take it from :func:`stamp_time`: the moment of writing, or, when the
environment sets ``SOURCE_DATE_EPOCH`` (https://reproducible-builds.org/specs/source-date-epoch/:
whole seconds since 1970-01-01 00:00 UTC), that moment, so that two builds of the same design
with the same tabletcad give the same bytes.  Every other varying part of those files (a DXF's
GUIDs, an SVG's element ids, the order of a STEP assembly's styles) is made a function of the
content, whatever the environment.
"""

from __future__ import annotations

import hashlib
import io
import os
import uuid
import zipfile
from datetime import datetime, timezone

__all__ = ["ENV", "stamp_time", "check_stamp", "content_uuid", "zip_date_time", "redate_zip"]

#: the environment variable of the reproducible-builds specification
ENV = "SOURCE_DATE_EPOCH"
_LAST = 253402300799  # 9999-12-31 23:59:59 UTC, the last second a datetime (and ISO 8601's four digits) holds
_ALLOWED = f"must be a whole number of seconds since 1970-01-01 00:00 UTC, 0 to {_LAST} (reproducible-builds.org)"


def stamp_time() -> datetime:
    """The time written into files, in UTC (timezone-aware, whole seconds).

    Returns
    -------
    datetime
        ``SOURCE_DATE_EPOCH`` when the environment sets it, else the current time.

    Raises
    ------
    DesignError
        ``SOURCE_DATE_EPOCH`` is set but is not a whole number of seconds in range.
    """
    raw = os.environ.get(ENV)
    if raw is None:
        return datetime.now(timezone.utc).replace(microsecond=0)
    text = raw.strip()
    if not (text.isascii() and text.isdigit()) or int(text) > _LAST:
        from tabletcad.errors import DesignError

        raise DesignError(ENV, raw, _ALLOWED)
    return datetime.fromtimestamp(int(text), timezone.utc)


def check_stamp() -> None:
    """Refuse a malformed ``SOURCE_DATE_EPOCH`` (a :class:`~tabletcad.errors.DesignError`) before anything is
    written; matplotlib reads it too, and would raise a bare ``ValueError`` while saving a picture."""
    stamp_time()


def content_uuid(*parts: bytes | str) -> uuid.UUID:
    """A name-based UUID (RFC 4122 version 5 layout) of ``parts``: the same content gives the same id.

    Parameters
    ----------
    parts
        Bytes or text (UTF-8) that the identifier stands for, in order.
    """
    h = hashlib.sha256()
    for p in parts:
        data = p.encode("utf-8") if isinstance(p, str) else bytes(p)
        h.update(len(data).to_bytes(8, "little"))
        h.update(data)
    return uuid.UUID(bytes=h.digest()[:16], version=5)


def zip_date_time(when: datetime) -> tuple[int, int, int, int, int, int]:
    """``when`` as a zip entry's ``date_time`` (UTC), clamped to the format's range 1980-2107."""
    low, high = datetime(1980, 1, 1, tzinfo=timezone.utc), datetime(2107, 12, 31, 23, 59, 58, tzinfo=timezone.utc)
    t = min(max(when.astimezone(timezone.utc), low), high)
    return (t.year, t.month, t.day, t.hour, t.minute, t.second)


def redate_zip(data: bytes, when: datetime | None = None) -> bytes:
    """The zip archive ``data`` with every entry dated ``when`` (default :func:`stamp_time`), else unchanged.

    A library that writes a zip by name (``ZipFile.writestr(name, ...)``, as openpyxl does for a workbook)
    dates each entry with the local time of writing; this gives its entries one date, in the same order,
    with the same contents, compression and permissions.

    Parameters
    ----------
    data : bytes
        A zip archive.
    when : datetime, optional
        The date (clamped to the zip format's 1980-2107, :func:`zip_date_time`).
    """
    stamp = zip_date_time(when if when is not None else stamp_time())
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w") as dst:
        for old in src.infolist():
            info = zipfile.ZipInfo(old.filename, date_time=stamp)
            info.compress_type, info.external_attr, info.comment = old.compress_type, old.external_attr, old.comment
            info.create_system = old.create_system
            dst.writestr(info, src.read(old))
    return out.getvalue()
