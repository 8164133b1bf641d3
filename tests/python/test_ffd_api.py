"""kodawari_native's FFD entry points: round trip at rest, shapes, and a bent axis."""

import kodawari_native as kn
import numpy as np
import pytest


def straight_axis(n=5, length=4.0):
    return np.column_stack([np.linspace(0.0, length, n), np.zeros(n), np.zeros(n)])


def box_mesh(count=5000, seed=3):
    rng = np.random.default_rng(seed)
    return (rng.random((count, 3)) * [4.0, 0.6, 0.4] - [0.0, 0.3, 0.2]).astype(np.float32)


def test_bind_then_deform_at_rest_rebuilds_the_mesh():
    axis = straight_axis()
    mesh = box_mesh()
    binding = kn.ffd_bind(axis, mesh)
    out = np.empty_like(mesh)
    binding.deform(axis, out)
    assert binding.count == len(mesh)
    assert np.abs(out - mesh).max() < 1e-5 * kn.curve_length(axis)


def test_binding_exposes_t_u_v_w_per_vertex():
    axis = straight_axis()
    mesh = np.array([[-0.5, 0.1, 0.0], [2.0, 0.2, -0.1], [4.5, 0.0, 0.3]], dtype=np.float32)
    binding = kn.ffd_bind(axis, mesh)
    for name in "tuvw":
        column = getattr(binding, name)
        assert column.dtype == np.float32 and column.shape == (3,)
    np.testing.assert_allclose(binding.t, [0.0, 0.5, 1.0], atol=1e-6)
    # Only the vertices beyond the ends keep an offset along the tangent.
    np.testing.assert_allclose(binding.w, [-0.5, 0.0, 0.5], atol=1e-6)


def test_bending_the_axis_bends_the_mesh_around_it():
    axis = straight_axis()
    mesh = box_mesh()
    binding = kn.ffd_bind(axis, mesh)
    bent = axis.copy()
    bent[3:, 1] += [0.5, 1.0]
    out = np.empty_like(mesh)
    binding.deform(bent, out)
    # Every vertex keeps its distance to the axis (the cross-section is rigid).
    t = binding.t.astype(np.float64)
    rest_distance = np.linalg.norm(mesh - kn.curve_points(axis, t), axis=1)
    interior = binding.w == 0
    bent_distance = np.linalg.norm(out - kn.curve_points(bent, t), axis=1)
    np.testing.assert_allclose(bent_distance[interior], rest_distance[interior], atol=1e-4)
    assert out[:, 1].max() > 0.9


def test_frames_are_orthonormal_with_e1_the_tangent():
    axis = straight_axis()
    axis[2, 2] = 1.0
    frames = kn.ffd_frames(axis, samples=33)
    assert frames.shape == (33, 4, 3) and frames.dtype == np.float64
    basis = frames[:, 1:, :]
    np.testing.assert_allclose(
        basis @ basis.transpose(0, 2, 1), np.broadcast_to(np.eye(3), (33, 3, 3)), atol=1e-9
    )
    np.testing.assert_allclose(
        frames[:, 0, :], kn.curve_points(axis, np.linspace(0, 1, 33)), atol=1e-12
    )


def test_preserve_lengths_restores_every_segment():
    points = straight_axis(6)
    rest = np.linalg.norm(np.diff(points, axis=0), axis=1)
    moved = points.copy()
    moved[2] += [0.3, 0.8, 0.0]
    kept = kn.preserve_lengths(moved, rest, 2)
    np.testing.assert_allclose(np.linalg.norm(np.diff(kept, axis=0), axis=1), rest, rtol=1e-12)
    np.testing.assert_array_equal(kept[2], moved[2])
    from_head = kn.preserve_lengths_from_head(moved, rest)
    np.testing.assert_array_equal(from_head[0], moved[0])
    np.testing.assert_allclose(np.linalg.norm(np.diff(from_head, axis=0), axis=1), rest, rtol=1e-12)


def test_wrong_control_point_count_raises():
    with pytest.raises(ValueError, match="control_points"):
        kn.ffd_bind(straight_axis(3), box_mesh(10))


def test_affine_coordinates_measure_each_packed_coordinate_and_fill_only_those_that_hold():
    # docs/algorithms.md §1.6: along a straight axis u and v are the rest position's offsets
    # (affine); s is not with evenly spaced points (the clamped spline's ends run faster).
    axis = straight_axis(6)
    mesh = box_mesh() + np.float32([0.0, 0.5, -0.25])  # an axis away from the origin
    binding = kn.ffd_bind(axis, mesh)
    end_scale = 1024 / 4.0
    rows, holds, worst = binding.affine_coordinates(mesh, end_scale, 1e-6)
    assert rows.dtype == np.float32 and rows.shape == (3, 4)
    assert holds == (False, True, True), worst
    assert worst[0] > 1e-3 and max(worst[1:]) <= 1e-6
    packed = binding.packed_coordinates(end_scale)
    filled = np.full_like(packed, 7.0)
    kn.ffd_fill_affine_coordinates(rows, holds, mesh, filled)
    assert np.all(filled[:, 0] == 7.0), "s does not hold: left as it was"
    assert np.abs(filled[:, 1:] - packed[:, 1:]).max() <= 1e-6 * 4.0
    with pytest.raises(ValueError, match="vertices"):
        binding.affine_coordinates(mesh[:-1], end_scale, 1e-6)
    with pytest.raises(ValueError, match="rows"):
        kn.ffd_fill_affine_coordinates(rows[:2], holds, mesh, filled)
    with pytest.raises(ValueError, match="packed"):
        kn.ffd_fill_affine_coordinates(rows, holds, mesh, filled[:-1])
    with pytest.raises(ValueError, match="holds"):
        kn.ffd_fill_affine_coordinates(rows, holds[:2], mesh, filled)
