"""Shared fixtures: the module under test, the shared meshes and the bunny's
camera and diffuse rays with their double-precision references."""
import numpy as np
import pytest

import rtcl
from meshes import load_obj, scenes_dir
from reference import Mesh, RayReference

# The benchmark camera of the bunny (bench/support/scene_catalog.cpp):
# eye, target, up, vertical field of view in degrees.
BUNNY_CAMERA = ((-0.0168, 0.110, 0.36), (-0.0168, 0.110, -0.0015), (0.0, 1.0, 0.0), 30.0)


def camera_rays(eye, target, up, fov_y_deg, width, height):
    """(height, width, 6) float32 rays through the pixel centres, rows from
    the top, unit directions: written here, independent of the module."""
    eye, target, up = (np.asarray(x, np.float64) for x in (eye, target, up))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    half_h = np.tan(0.5 * np.radians(fov_y_deg))
    half_w = half_h * width / height
    sx = (2.0 * (np.arange(width) + 0.5) / width - 1.0) * half_w
    sy = (1.0 - 2.0 * (np.arange(height) + 0.5) / height) * half_h
    d = forward + sx[None, :, None] * right + sy[:, None, None] * true_up
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    rays = np.concatenate([np.broadcast_to(eye, d.shape), d], axis=2)
    return rays.astype(np.float32)


def with_bounds(rays, tmin=0.0, tmax=np.inf):
    flat = rays.reshape(-1, 6).astype(np.float64)
    return np.concatenate([flat, np.full((len(flat), 1), tmin), np.full((len(flat), 1), tmax)], axis=1)


def diffuse_rays(mesh, rays, reference, seed=1):
    """One cosine-distributed bounce from each clear hit of `rays` (n, 6),
    leaving the surface by 1e-4 of the point's magnitude along the facing
    normal: float32 (m, 6)."""
    hit = np.nonzero(np.isfinite(reference.closest_t))[0]
    o = rays[hit, :3].astype(np.float64)
    d = rays[hit, 3:6].astype(np.float64)
    p = o + reference.closest_t[hit, None] * d
    # The triangle of the nearest clear hit of each ray.
    sel = reference.clear
    order = np.lexsort((reference.t[sel], reference.ray[sel]))
    ray_sorted, tri_sorted = reference.ray[sel][order], reference.tri[sel][order]
    first = np.searchsorted(ray_sorted, hit)
    n = np.cross(mesh.e1[tri_sorted[first]], mesh.e2[tri_sorted[first]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n[np.einsum("ij,ij->i", n, d) > 0] *= -1.0
    rng = np.random.default_rng(seed)
    u1, u2 = rng.random(len(hit)), rng.random(len(hit))
    t1 = np.cross(n, np.where(np.abs(n[:, :1]) > 0.5, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]]))
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(n, t1)
    r, phi = np.sqrt(u1), 2.0 * np.pi * u2
    dirs = (r * np.cos(phi))[:, None] * t1 + (r * np.sin(phi))[:, None] * t2 + np.sqrt(1.0 - u1)[:, None] * n
    offset = 1e-4 * np.maximum(np.max(np.abs(p), axis=1), 1e-2 * mesh.magnitude)
    origins = p + offset[:, None] * n
    return np.concatenate([origins, dirs], axis=1).astype(np.float32)


@pytest.fixture(scope="session")
def bunny_arrays():
    path = scenes_dir() / "stanford_bunny" / "bunny.obj"
    if not path.exists():
        pytest.skip(f"{path} not found (set RTCL_SCENES_DIR)")
    return load_obj(path)


@pytest.fixture(scope="session")
def dragon_arrays():
    path = scenes_dir() / "stanford_dragon_100k" / "dragon.obj"
    if not path.exists():
        pytest.skip(f"{path} not found (set RTCL_SCENES_DIR)")
    return load_obj(path)


@pytest.fixture(scope="session")
def bunny_mesh(bunny_arrays):
    return Mesh(*bunny_arrays)


@pytest.fixture(scope="session")
def bunny_scene(bunny_arrays):
    scene = rtcl.RaycastingScene()
    assert scene.add_triangles(*bunny_arrays) == 0
    return scene


@pytest.fixture(scope="session")
def bunny_camera(bunny_mesh):
    """The bunny's camera rays (32 x 32) and their reference."""
    rays = camera_rays(*BUNNY_CAMERA, 32, 32)
    return rays, RayReference(bunny_mesh, with_bounds(rays))


@pytest.fixture(scope="session")
def bunny_diffuse(bunny_mesh, bunny_camera):
    """Two diffuse bounces from each of the camera rays' hits and their reference."""
    rays, reference = bunny_camera
    diffuse = np.concatenate([diffuse_rays(bunny_mesh, rays.reshape(-1, 6), reference, seed) for seed in (1, 2)])
    return diffuse, RayReference(bunny_mesh, with_bounds(diffuse))
