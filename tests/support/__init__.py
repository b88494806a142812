"""Test support, outside the library: independent read-back of written files (OCP in a fresh
process, FreeCAD's own reader) and analytic stand-in surfaces (sphere, cylinder, ring)."""
