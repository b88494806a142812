"""File input/output helpers shared by every writer in tabletcad."""

from tabletcad.io.atomic import atomic_path, atomic_write_bytes, atomic_write_text

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text"]
