"""The tooling gap's point-to-mesh distance (libigl's AABB tree) against a brute-force minimum
over every triangle computed by a second library (trimesh's closest point on each triangle)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("igl")
trimesh = pytest.importorskip("trimesh")

from tabletcad.tooling.interference import mesh_distance  # noqa: E402

pytestmark = pytest.mark.cad


def _brute_force(P: np.ndarray, V: np.ndarray, T: np.ndarray) -> np.ndarray:
    tri = V[T]  # (m, 3, 3)
    out = np.empty(len(P))
    for i, p in enumerate(P):
        q = trimesh.triangles.closest_point(tri, np.repeat(p[None], len(tri), axis=0))
        out[i] = np.min(np.linalg.norm(q - p, axis=1))
    return out


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), noise=st.floats(0.0, 0.3), spread=st.floats(0.01, 3.0))
def test_mesh_distance_is_the_exact_minimum_over_all_triangles(seed, noise, spread):
    rng = np.random.default_rng(seed)
    mesh = trimesh.creation.icosphere(subdivisions=2)
    V = np.asarray(mesh.vertices) * (1.0 + noise * rng.uniform(-1, 1, (len(mesh.vertices), 1)))
    T = np.asarray(mesh.faces)
    P = rng.normal(size=(60, 3)) * spread
    assert np.allclose(mesh_distance(P, V, T), _brute_force(P, V, T), rtol=0, atol=1e-12)


def test_mesh_distance_of_points_on_the_mesh_and_of_nothing():
    mesh = trimesh.creation.box(extents=(2.0, 3.0, 4.0))
    V, T = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    assert np.max(mesh_distance(V, V, T)) <= 1e-15
    centre = mesh_distance(np.zeros((1, 3)), V, T)
    assert centre[0] == pytest.approx(1.0, abs=1e-15)  # the nearest face is x = ±1
    assert mesh_distance(np.zeros((0, 3)), V, T).shape == (0,)
    assert np.isinf(mesh_distance(np.zeros((2, 3)), V, T[:0])).all()
