"""Shared fixtures: the module under test, the shared meshes and the bunny's
camera and diffuse rays with their double-precision references.

Under ctest (python/CMakeLists.txt sets RTCL_TESTS_NO_SKIP=1) a skipped test
is a failure: the Open3D comparisons and the comparison with `rtcl render`
cannot drop out of the suite unnoticed. By hand, without Open3D or
RTCL_CLI, they are skipped. A missing mesh fails everywhere (meshes.mesh_file)."""
import os

import numpy as np
import pytest

import rtcl
from meshes import load_obj, mesh_file
from reference import Mesh, RayReference

NO_SKIP = os.environ.get("RTCL_TESTS_NO_SKIP") == "1"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """With RTCL_TESTS_NO_SKIP=1, a skip (importorskip, skipif, pytest.skip)
    is reported as a failure with its reason."""
    outcome = yield
    report = outcome.get_result()
    if NO_SKIP and report.skipped and not hasattr(report, "wasxfail"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        report.outcome = "failed"
        report.longrepr = f"skipped, and RTCL_TESTS_NO_SKIP=1 (ctest) makes a skip a failure: {reason}"


def pytest_sessionfinish(session, exitstatus):
    """Skips outside a test (a whole module at collection) fail the run too."""
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    skipped = reporter.stats.get("skipped") if reporter is not None else None
    if NO_SKIP and skipped and session.exitstatus == 0:
        reporter.write_line(f"\nRTCL_TESTS_NO_SKIP=1 (ctest): {len(skipped)} skipped, which fails the run", red=True)
        session.exitstatus = 1

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
    return load_obj(mesh_file("stanford_bunny/bunny.obj"))


@pytest.fixture(scope="session")
def dragon_arrays():
    return load_obj(mesh_file("stanford_dragon_100k/dragon.obj"))


@pytest.fixture(scope="session")
def o3d():
    """Open3D (python3-open3d), the reference of the point queries and
    camera rays: skipped without it by hand, a failure under ctest."""
    return pytest.importorskip("open3d")


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
