"""Reading a user's TOML file: every problem with it is one :class:`~tabletcad.errors.DesignError`."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from tabletcad.errors import DesignError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["read_toml_file", "loads_toml"]


def loads_toml(text: str, parameter: str, name: str) -> dict[str, Any]:
    """``tomllib.loads(text)``; invalid TOML, nesting too deep for the parser (a RecursionError) and an
    integer literal longer than Python converts are a :class:`DesignError` of ``parameter`` = ``name``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DesignError(parameter, name, f"must be valid TOML ({exc})") from None
    except RecursionError:
        raise DesignError(parameter, name, "must be valid TOML nested less than a few hundred levels deep") from None
    except ValueError as exc:  # e.g. an integer of more than 4300 digits
        raise DesignError(parameter, name, f"must be valid TOML with numbers Python can read ({exc})") from None


def read_toml_file(path: str | Path, parameter: str) -> dict[str, Any]:
    """The parsed TOML of the file ``path``; a folder, a missing or unreadable file, text that is not
    UTF-8 (a byte-order mark is allowed) and what :func:`loads_toml` refuses are a :class:`DesignError`
    of ``parameter``."""
    path = Path(path)
    if path.is_dir():
        raise DesignError(parameter, str(path), "must be a TOML file, not a folder")
    if not path.is_file():  # (a pipe, such as bash's <(...), or a device exists but is not a file)
        raise DesignError(parameter, str(path), "must be a TOML file, not a pipe or device" if path.exists()
                          else "must be an existing TOML file")
    try:
        text = path.read_text(encoding="utf-8-sig")  # a byte-order mark, as some editors write it, is not TOML
    except UnicodeDecodeError:
        raise DesignError(parameter, str(path), "must be UTF-8 text (TOML)") from None
    except OSError as exc:
        raise DesignError(parameter, str(path), f"must be a readable file ({exc.strerror})") from None
    return loads_toml(text, parameter, path.name)
