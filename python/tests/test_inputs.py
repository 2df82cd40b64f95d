"""What the module accepts and refuses: leading shapes, dtypes and strides,
NaN and infinite rays, empty arrays, bad arguments (refused before any work,
the scene unchanged), devices, and calls from several threads. Answers are
checked against closed forms on the cube [-1, 1]^3."""
import threading

import numpy as np
import pytest

import rtcl
from meshes import cube_grid

INVALID = rtcl.RaycastingScene.INVALID_ID


@pytest.fixture(scope="module")
def cube():
    scene = rtcl.RaycastingScene()
    scene.add_triangles(*cube_grid(2))
    return scene


def down_rays(n, seed=0):
    """Rays from z = 5 straight down at x, y in (-0.9, 0.9): t = 4, 2 crossings."""
    xy = np.random.default_rng(seed).uniform(-0.9, 0.9, (n, 2))
    return np.concatenate([xy, np.full((n, 1), 5.0), np.zeros((n, 2)), -np.ones((n, 1))], axis=1)


def test_leading_shapes(cube):
    rays = down_rays(24).astype(np.float32)
    for shape in [(24,), (4, 6), (2, 3, 4)]:
        r = rays.reshape(shape + (6,))
        ans = cube.cast_rays(r)
        assert ans["t_hit"].shape == shape and np.all(ans["t_hit"] == 4.0)
        assert ans["primitive_uvs"].shape == shape + (2,)
        assert ans["primitive_normals"].shape == shape + (3,)
        assert cube.test_occlusions(r).shape == shape
        assert cube.count_intersections(r).shape == shape
        assert cube.list_intersections(r)["ray_splits"].shape == (25,)
        p = r[..., :3]
        assert cube.compute_distance(p).shape == shape
        assert cube.compute_closest_points(p)["points"].shape == shape + (3,)
        assert cube.compute_signed_distance(p).shape == shape
    one = cube.cast_rays(rays[0])  # a single ray: 0-d answers
    assert one["t_hit"].shape == () and one["t_hit"] == 4.0


def test_float64_and_strided_input(cube):
    rays = down_rays(50)
    ans = cube.cast_rays(rays)  # float64
    assert np.all(ans["t_hit"] == 4.0)
    wide = np.zeros((50, 12))
    wide[:, ::2] = rays  # every other column: a non-contiguous last axis
    assert np.all(cube.cast_rays(wide[:, ::2])["t_hit"] == 4.0)
    transposed = np.asfortranarray(rays.astype(np.float32))
    assert np.all(cube.count_intersections(transposed) == 2)
    assert np.all(cube.cast_rays(rays[::-3])["t_hit"] == 4.0)
    assert np.all(cube.test_occlusions(rays.tolist()))  # lists go through numpy
    # Points the same way: distances to the top face.
    p = rays[:, :3].copy()
    assert np.allclose(cube.compute_distance(p[::2]), 4.0)
    assert np.allclose(cube.compute_distance(np.asfortranarray(p)), 4.0)
    # Unaligned float32 values inside a byte buffer.
    raw = np.zeros(50 * 24 + 1, np.uint8)
    unaligned = raw[1:].view(np.float32).reshape(50, 6)
    unaligned[:] = rays
    assert np.all(cube.cast_rays(unaligned)["t_hit"] == 4.0)


def test_invalid_rays_are_misses(cube):
    rays = down_rays(6).astype(np.float32)
    rays[0, 0] = np.nan
    rays[1, 5] = np.nan
    rays[2, 3:] = 0.0  # no direction
    rays[3, 2] = np.inf
    rays[4, 4] = -np.inf
    ans = cube.cast_rays(rays)
    assert np.all(ans["t_hit"][:5] == np.inf) and ans["t_hit"][5] == 4.0
    assert np.all(ans["geometry_ids"][:5] == INVALID) and np.all(ans["primitive_ids"][:5] == INVALID)
    assert np.all(ans["primitive_uvs"][:5] == 0) and np.all(ans["primitive_normals"][:5] == 0)
    assert cube.test_occlusions(rays).tolist() == [False] * 5 + [True]
    assert cube.count_intersections(rays).tolist() == [0] * 5 + [2]
    assert cube.list_intersections(rays)["ray_splits"].tolist() == [0, 0, 0, 0, 0, 0, 2]


def test_empty_inputs(cube):
    for shape in [(0,), (3, 0)]:
        rays = np.zeros(shape + (6,), np.float32)
        ans = cube.cast_rays(rays)
        assert ans["t_hit"].shape == shape and ans["primitive_normals"].shape == shape + (3,)
        assert cube.test_occlusions(rays).shape == shape
        assert cube.count_intersections(rays).shape == shape
        every = cube.list_intersections(rays)
        assert every["ray_splits"].tolist() == [0] and every["t_hit"].shape == (0,)
        assert every["primitive_uvs"].shape == (0, 2)
        points = np.zeros(shape + (3,), np.float64)
        assert cube.compute_distance(points).shape == shape
        assert cube.compute_occupancy(points).shape == shape
        assert cube.compute_closest_points(points)["primitive_uvs"].shape == shape + (2,)


@pytest.mark.parametrize("call", ["cast_rays", "test_occlusions", "count_intersections", "list_intersections"])
def test_bad_rays_are_refused(cube, call):
    method = getattr(cube, call)
    with pytest.raises(ValueError, match=rf"{call}: rays has shape \(4, 5\); expected \(\.\.\., 6\)"):
        method(np.zeros((4, 5), np.float32))
    with pytest.raises(ValueError, match="expected"):
        method(np.zeros((), np.float32))
    with pytest.raises(TypeError, match=rf"{call}: rays has dtype int64; expected float32 or float64"):
        method(np.zeros((4, 6), np.int64))
    with pytest.raises(TypeError, match="float16"):
        method(np.zeros((4, 6), np.float16))
    with pytest.raises(TypeError):
        method("rays")
    with pytest.raises(ValueError, match="nthreads"):
        method(np.zeros((4, 6), np.float32), nthreads=-1)


@pytest.mark.parametrize("call", ["compute_distance", "compute_closest_points", "compute_signed_distance",
                                  "compute_occupancy"])
def test_bad_points_are_refused(cube, call):
    method = getattr(cube, call)
    with pytest.raises(ValueError, match=rf"{call}: query_points has shape \(4, 2\); expected \(\.\.\., 3\)"):
        method(np.zeros((4, 2), np.float32))
    with pytest.raises(TypeError, match="dtype"):
        method(np.zeros((4, 3), np.int32))
    p = np.zeros((2, 3, 3), np.float32)
    p[1, 2, 0] = np.nan
    with pytest.raises(ValueError, match=rf"{call}: query_points\[1, 2\] has a NaN or infinite coordinate"):
        method(p)
    with pytest.raises(ValueError, match="NaN or infinite"):
        method(np.array([[0.0, 1e300, 0.0]]))  # beyond float's range


@pytest.mark.parametrize("call", ["compute_signed_distance", "compute_occupancy"])
def test_nsamples_must_be_odd(cube, call):
    for n in (0, 2, -1):
        with pytest.raises(ValueError, match=rf"{call}: nsamples is {n}; must be odd"):
            getattr(cube, call)(np.zeros((1, 3), np.float32), nsamples=n)


def test_bad_bounds_are_refused(cube):
    rays = down_rays(2).astype(np.float32)
    with pytest.raises(ValueError, match="cast_rays: tnear is NaN"):
        cube.cast_rays(rays, tnear=float("nan"))
    with pytest.raises(ValueError, match="test_occlusions: tfar is NaN"):
        cube.test_occlusions(rays, tfar=float("nan"))


def test_bad_meshes_leave_the_scene_unchanged():
    scene = rtcl.RaycastingScene()
    v, f = cube_grid(2)
    scene.add_triangles(v, f)
    bad_index = f.copy()
    bad_index[3, 1] = len(v)
    with pytest.raises(ValueError, match=r"add_triangles: triangle 3 uses vertex index"):
        scene.add_triangles(v, bad_index)
    nan_vertex = v.copy()
    nan_vertex[5, 2] = np.nan
    with pytest.raises(ValueError, match="add_triangles: vertex 5 has a NaN or infinite coordinate"):
        scene.add_triangles(nan_vertex, f)
    with pytest.raises(ValueError, match=r"triangle_indices\[0\] has index -1"):
        scene.add_triangles(v, -np.ones((1, 3), np.int64))
    with pytest.raises(TypeError, match="triangle_indices has dtype float32"):
        scene.add_triangles(v, f.astype(np.float32))
    with pytest.raises(TypeError, match="vertex_positions has dtype int64"):
        scene.add_triangles(v.astype(np.int64), f)
    with pytest.raises(ValueError, match=r"vertex_positions has shape \(26, 2\); expected \(N, 3\)"):
        scene.add_triangles(v[:, :2], f)
    with pytest.raises(ValueError, match=r"vertex_positions has shape \(2, 13, 3\); expected \(N, 3\)"):
        scene.add_triangles(v.reshape(2, 13, 3), f)
    with pytest.raises(ValueError, match=r"triangle_indices has shape \(48, 2\); expected \(M, 3\)"):
        scene.add_triangles(v, f[:, :2])
    assert scene.geometry_count == 1
    rays = down_rays(3)
    ans = scene.cast_rays(rays)
    assert np.all(ans["t_hit"] == 4.0) and np.all(ans["geometry_ids"] == 0)
    assert scene.add_triangles(v, f.astype(np.int64)) == 1  # any integer dtype


def test_scene_arguments():
    with pytest.raises(ValueError, match='accel "nope": unknown acceleration structure'):
        rtcl.RaycastingScene(accel="nope")
    with pytest.raises(ValueError, match='accel "grid:lambda=-1": lambda must be'):
        rtcl.RaycastingScene(accel="grid:lambda=-1")
    with pytest.raises(ValueError, match='precision "sloppy": unknown precision level'):
        rtcl.RaycastingScene(precision="sloppy")
    with pytest.raises(ValueError, match='device "999": no such device'):
        rtcl.RaycastingScene(device=999)
    with pytest.raises(ValueError, match='device "no such name": no device name matches'):
        rtcl.RaycastingScene(device="no such name")
    with pytest.raises(TypeError, match="device must be None, an index or a name"):
        rtcl.RaycastingScene(device=1.5)
    with pytest.raises(TypeError):
        rtcl.RaycastingScene(4)  # Open3D's positional nthreads: every argument is a keyword here
    scene = rtcl.RaycastingScene(device=0, accel="bvh-packet", precision="exact" if rtcl.devices()[0]["fp64"]
                                 else "fast", nthreads=2)
    assert "bvh-packet" in repr(scene)


def test_other_structures_and_levels():
    """The ray queries on every level and on a non-BVH structure; queries a
    structure lacks name it."""
    rays = down_rays(64)
    for precision in ("fast", "robust"):
        scene = rtcl.RaycastingScene(precision=precision)
        scene.add_triangles(*cube_grid(2))
        assert np.allclose(scene.cast_rays(rays)["t_hit"], 4.0, atol=1e-6)
    grid = rtcl.RaycastingScene(accel="grid")
    grid.add_triangles(*cube_grid(2))
    assert np.all(grid.cast_rays(rays)["t_hit"] == 4.0)
    assert np.all(grid.test_occlusions(rays))
    with pytest.raises(RuntimeError, match="count: structure grid does not support this query"):
        grid.count_intersections(rays)


def test_devices():
    devices = rtcl.devices()
    assert len(devices) >= 1
    assert {"index", "platform", "name", "type", "version", "compute_units", "global_mem_bytes",
            "max_alloc_bytes", "fp64"} <= set(devices[0])
    assert [d["index"] for d in devices] == list(range(len(devices)))
    assert rtcl.RaycastingScene.INVALID_ID == 2**32 - 1
    assert isinstance(rtcl.__version__, str)


def test_several_threads(cube):
    """4 threads x 25 mixed calls on one scene, each answer checked."""
    errors = []
    rng = np.random.default_rng(9)

    def work(seed):
        try:
            local = np.random.default_rng(seed)
            for k in range(25):
                rays = down_rays(int(local.integers(1, 3000)), seed=seed * 100 + k)
                kind = k % 4
                if kind == 0:
                    assert np.all(cube.cast_rays(rays, coherent=bool(k % 8))["t_hit"] == 4.0)
                elif kind == 1:
                    assert np.all(cube.count_intersections(rays) == 2)
                elif kind == 2:
                    assert np.all(cube.test_occlusions(rays))
                else:
                    p = rays[:, :3] * np.array([1.0, 1.0, 0.2])  # z = 1: on the top face
                    assert np.allclose(cube.compute_distance(p), 0.0, atol=1e-6)
        except Exception as e:  # reported by the main thread
            errors.append(e)

    threads = [threading.Thread(target=work, args=(int(rng.integers(1, 1000)),)) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors[0]


def test_threads_adding_meshes_while_others_query():
    """Queries see the meshes of some moment, never a half-built scene."""
    scene = rtcl.RaycastingScene()
    v, f = cube_grid(2)
    scene.add_triangles(v, f)
    errors = []

    def query():
        try:
            for _ in range(20):
                ans = scene.cast_rays(down_rays(500))
                assert np.all(ans["t_hit"] == 4.0)
        except Exception as e:
            errors.append(e)

    def add():
        try:
            for k in range(1, 6):
                scene.add_triangles(v + np.float32(10.0 * k), f)  # away from the rays
        except Exception as e:
            errors.append(e)

    threads = [threading.Thread(target=query), threading.Thread(target=query), threading.Thread(target=add)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors[0]
    assert scene.geometry_count == 6


@pytest.mark.parametrize("n", [32_768, 32_769, 49_152, 50_000, 262_144, 1_100_000])
def test_split_calls_answer_every_ray_in_place(cube, n):
    """Calls of 3 x 2^14 rays and more run in chunks of several sizes (a
    ramp up, equal chunks, a ramp down): every ray's answer lands in its
    place, at both ends and around each chunk bound."""
    rays = down_rays(n, seed=n).astype(np.float32)
    beside = np.unique(np.r_[0, n - 1, np.arange(7, n, 4099), np.arange(16_384, n, 16_384) - 1])
    rays[beside, 0] = 5.0  # beside the cube: misses
    ans = cube.cast_rays(rays)
    expected = np.full(n, 4.0, np.float32)
    expected[beside] = np.inf
    assert np.array_equal(ans["t_hit"], expected)
    assert np.array_equal(cube.test_occlusions(rays), expected == 4.0)


def test_calls_larger_than_one_chunk(cube):
    """Calls of more rays or points than one library call takes (2^18) run
    in chunks: every chunk's answers land in their places."""
    n = 700_000
    rays = down_rays(n, seed=4)
    rays[123_456, 3:] = 0.0  # one miss, in an early chunk
    rays[654_321, 0] = 5.0  # and one in a late one, beside the cube
    shaped = np.asfortranarray(rays).reshape(2, n // 2, 6, order="F")[:, ::-1]  # float64, strided
    flat = shaped.reshape(-1, 6)
    miss = ~((np.abs(flat[:, 0]) < 1.0) & (flat[:, 5] != 0.0))
    assert miss.sum() == 2
    ans = cube.cast_rays(shaped, coherent=True)
    assert ans["t_hit"].shape == (2, n // 2)
    t = ans["t_hit"].reshape(-1)
    assert np.all(t[~miss] == 4.0) and np.all(t[miss] == np.inf)
    assert np.array_equal(cube.test_occlusions(shaped).reshape(-1), ~miss)
    assert np.array_equal(cube.count_intersections(shaped).reshape(-1), np.where(miss, 0, 2))
    points = flat[:, :3] * np.array([1.0, 1.0, 0.2])  # on the plane z = 1
    d = cube.compute_distance(points)
    assert np.allclose(d[~miss], 0.0, atol=1e-6) and np.isclose(d[miss][1], 4.0)
    closest = cube.compute_closest_points(points)["points"]
    assert np.allclose(closest[~miss], points[~miss], atol=1e-6)
    inside = points * np.array([1.0, 1.0, 0.5])
    expected = np.all(np.abs(inside) < 1.0, axis=1).astype(np.float32)
    assert expected.sum() == n - 1
    assert np.array_equal(cube.compute_occupancy(inside), expected)
    bad = points.copy()
    bad[600_001, 1] = np.inf  # in a late chunk: refused before the first
    with pytest.raises(ValueError, match=r"compute_distance: query_points\[600001\] has a NaN or infinite"):
        cube.compute_distance(bad)


def swapped(a, dtype):
    """`a` as `dtype` in the byte order that is not this machine's ('>f4'
    on x86): the same values, other bytes."""
    out = np.asarray(a).astype(np.dtype(dtype).newbyteorder("S"))
    assert not out.dtype.isnative
    return out


def same_answers(a, b):
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        for key in a:
            assert np.array_equal(a[key], b[key]), key
    else:
        assert np.array_equal(a, b)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_non_native_byte_order_rays_and_points(dtype):
    """Rays and points in the other byte order give the native arrays'
    answers, for every query (numpy converts them first), strided too."""
    from meshes import icosphere
    scene = rtcl.RaycastingScene()
    scene.add_triangles(*icosphere(2))
    rng = np.random.default_rng(21)
    o = rng.uniform(-2.0, 2.0, (300, 3))
    rays = np.concatenate([o, rng.normal(size=(300, 3))], axis=1).astype(dtype)
    other = swapped(rays, dtype)
    native = scene.cast_rays(rays)
    assert 30 < np.isfinite(native["t_hit"]).sum() < 270  # hits and misses
    same_answers(native, scene.cast_rays(other))
    same_answers(scene.cast_rays(rays.reshape(3, 100, 6)[:, ::2]), scene.cast_rays(other.reshape(3, 100, 6)[:, ::2]))
    same_answers(scene.cast_rays(rays[::3]), scene.cast_rays(np.asfortranarray(other)[::3]))
    same_answers(scene.cast_rays(rays, coherent=True), scene.cast_rays(other, coherent=True))
    same_answers(scene.test_occlusions(rays, tfar=1.0), scene.test_occlusions(other, tfar=1.0))
    same_answers(scene.count_intersections(rays), scene.count_intersections(other))
    same_answers(scene.list_intersections(rays), scene.list_intersections(other))
    points = rays[:, :3]
    other_points = swapped(points, dtype)
    same_answers(scene.compute_distance(points), scene.compute_distance(other_points))
    same_answers(scene.compute_closest_points(points), scene.compute_closest_points(other_points))
    same_answers(scene.compute_signed_distance(points, nsamples=3),
                 scene.compute_signed_distance(other_points, nsamples=3))
    same_answers(scene.compute_occupancy(points), scene.compute_occupancy(other_points))
    # NaN points are found in the other byte order too.
    bad = other_points.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"compute_distance: query_points\[7\] has a NaN"):
        scene.compute_distance(bad)


@pytest.mark.parametrize("vdtype,tdtype", [(np.float32, np.uint32), (np.float64, np.int64)])
@pytest.mark.parametrize("which", ["vertices", "triangles", "transforms", "updated vertices"])
def test_non_native_byte_order_meshes_and_transforms(vdtype, tdtype, which):
    """Vertices, triangle indices, transforms (4, 4) and (3, 4), and updated
    vertices, each in turn in the other byte order, build the scene the
    native arrays build."""
    from meshes import icosphere
    v, f = icosphere(2)
    v = (v * np.array([1.0, 0.7, 1.3], np.float32) + np.float32(0.25)).astype(vdtype)
    m = np.eye(4)
    m[:3, :3] = [[0.0, -1.0, 0.0], [0.8, 0.0, 0.0], [0.0, 0.0, 1.5]]
    m[:3, 3] = [3.0, -0.5, 0.25]
    moved = np.eye(4)
    moved[:3, 3] = [-3.0, 0.5, 0.0]
    wobble = v * vdtype(1.1)
    rng = np.random.default_rng(22)
    o = rng.uniform(-5.0, 5.0, (2000, 3))
    rays = np.concatenate([o, rng.uniform(-3.0, 3.0, (2000, 3)) - o], axis=1).astype(np.float32)
    native = lambda a, t: np.asarray(a, t)
    answers = []
    for convert in (native, swapped):
        def given(kind, a, t):
            return (convert if kind == which else native)(a, t)
        scene = rtcl.RaycastingScene()
        assert scene.add_triangles(given("vertices", v, vdtype), given("triangles", f, tdtype)) == 0
        flat = scene.cast_rays(rays)
        points = scene.compute_closest_points(rays[:, :3])
        scene.add_instance(0, given("transforms", m, vdtype))
        scene.add_instance(0, given("transforms", np.c_[m[:3, :3], [0.0, 3.0, 0.0]], vdtype))  # (3, 4)
        placed = scene.cast_rays(rays)
        scene.set_transform(1, given("transforms", moved, vdtype))
        scene.update_vertices(0, given("updated vertices", wobble, vdtype))
        answers.append((flat, points, placed, scene.cast_rays(rays)))
    for native_answer, other_answer in zip(*answers):
        same_answers(native_answer, other_answer)
    flat, _, placed, last = answers[0]
    assert np.isfinite(flat["t_hit"]).sum() > 100
    assert set(np.unique(placed["instance_ids"])) == {0, 1, INVALID}  # every placement is hit
    assert set(np.unique(last["instance_ids"])) == {0, 1, INVALID}
