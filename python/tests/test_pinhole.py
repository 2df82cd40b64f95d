"""create_rays_pinhole against Open3D's, both signatures, and the camera
geometry it promises."""
import numpy as np
import pytest

import rtcl

RS = rtcl.RaycastingScene


def close(a, b):
    scale = np.maximum(1.0, np.abs(b))
    return np.max(np.abs(a - b) / scale) < 1e-5


def test_intrinsic_extrinsic_against_open3d(o3d):
    k = np.array([[500.0, 2.0, 320.0], [0.0, 480.0, 241.0], [0.0, 0.0, 1.0]])
    angle = 0.3
    r = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0], [-np.sin(angle), 0.0, np.cos(angle)]])
    e = np.eye(4)
    e[:3, :3], e[:3, 3] = r, [0.5, -1.0, 2.0]
    ours = RS.create_rays_pinhole(k, e, 64, 48)
    ref = o3d.t.geometry.RaycastingScene.create_rays_pinhole(o3d.core.Tensor(k), o3d.core.Tensor(e), 64, 48).numpy()
    assert ours.shape == (48, 64, 6) and ours.dtype == np.float32
    assert close(ours, ref)
    # Keywords as Open3D names them; float32 and list inputs.
    again = RS.create_rays_pinhole(intrinsic_matrix=k.astype(np.float32).tolist(), extrinsic_matrix=e,
                                   width_px=64, height_px=48)
    assert close(again, ref)


@pytest.mark.parametrize("up", [(0, 1, 0), (0, 0, 1), (1, 1, 0)])
def test_look_at_against_open3d(o3d, up):
    center, eye = np.array([0.2, 0.1, 0.0]), np.array([1.0, 2.0, 3.0])
    ours = RS.create_rays_pinhole(fov_deg=70.0, center=center, eye=eye, up=up, width_px=40, height_px=30)
    ref = o3d.t.geometry.RaycastingScene.create_rays_pinhole(
        70.0, o3d.core.Tensor(center.astype(np.float32)), o3d.core.Tensor(eye.astype(np.float32)),
        o3d.core.Tensor(np.array(up, np.float32)), 40, 30).numpy()
    assert ours.shape == (30, 40, 6)
    assert close(ours, ref)


def test_look_at_geometry():
    """The optical axis passes through the centre; the horizontal field of
    view spans fov_deg between the outer pixel edges."""
    rays = RS.create_rays_pinhole(90.0, [0, 0, 0], [0, 0, 5], [0, 1, 0], 64, 48)
    assert np.all(rays[..., :3] == [0, 0, 5])
    d = rays[..., 3:].astype(np.float64)
    assert np.allclose(d[..., 2], -1.0)  # unit depth along the axis
    # Focal length 32 px; pixel centres at x + 0.5 and y + 0.5.
    assert np.isclose(abs(d[24, 0, 0]), 31.5 / 32, atol=1e-6)
    assert np.isclose(abs(d[24, 0, 1]), 0.5 / 32, atol=1e-6)
    assert np.isclose(abs(d[0, 32, 1]), 23.5 / 32, atol=1e-6)
    assert np.isclose(abs(d[0, 32, 0]), 0.5 / 32, atol=1e-6)


def test_bad_camera_arguments():
    k = np.eye(3)
    with pytest.raises(ValueError, match=r"intrinsic_matrix has shape \(2, 2\); expected \(3, 3\)"):
        RS.create_rays_pinhole(np.eye(2), np.eye(4), 4, 4)
    with pytest.raises(ValueError, match="intrinsic_matrix is singular"):
        RS.create_rays_pinhole(np.zeros((3, 3)), np.eye(4), 4, 4)
    with pytest.raises(ValueError, match="extrinsic_matrix has a NaN"):
        RS.create_rays_pinhole(k, np.full((4, 4), np.nan), 4, 4)
    with pytest.raises(ValueError, match="width_px is -1"):
        RS.create_rays_pinhole(k, np.eye(4), -1, 4)
    with pytest.raises(ValueError, match="fov_deg is 180"):
        RS.create_rays_pinhole(180.0, [0, 0, 0], [0, 0, 1], [0, 1, 0], 4, 4)
    with pytest.raises(ValueError, match="center equals eye"):
        RS.create_rays_pinhole(60.0, [0, 0, 1], [0, 0, 1], [0, 1, 0], 4, 4)
    with pytest.raises(ValueError, match="up is parallel"):
        RS.create_rays_pinhole(60.0, [0, 0, 0], [0, 0, 1], [0, 0, 2], 4, 4)
    with pytest.raises(TypeError):
        RS.create_rays_pinhole(60.0, "centre", [0, 0, 1], [0, 1, 0], 4, 4)
