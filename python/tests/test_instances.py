"""Instances (add_instance, set_transform, update_vertices): against the
same triangles transformed here in double precision, through the
double-precision brute force of reference.py and through pre-transformed
copies added with add_triangles."""
import threading

import numpy as np
import pytest

import rtcl
from meshes import cube_grid, icosphere
from reference import Mesh, RayReference, point_triangle_distance
from conftest import with_bounds

INVALID = rtcl.RaycastingScene.INVALID_ID

# Affine maps as (4, 4): a rotation with a translation, a mirror with a
# translation, a non-uniform scale with a rotation (all non-singular).


def rotation(degrees, axis):
    axis = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    x, y, z = axis
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) * c + s * k + (1 - c) * np.outer(axis, axis)


def affine(linear, shift):
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = linear, shift
    return m


TRANSFORMS = [
    affine(rotation(30.0, (1, 2, 3)), (3.0, 0.5, -1.0)),
    affine(np.diag([-1.0, 1.0, 1.0]) @ rotation(-50.0, (0, 1, 0)), (-3.0, 0.0, 0.5)),  # mirrored
    affine(rotation(20.0, (0, 0, 1)) @ np.diag([2.0, 0.5, 1.25]), (0.0, 3.0, 0.0)),  # non-uniform scale
]


def placed(vertices, m):
    v = np.asarray(vertices, np.float64)
    return v @ m[:3, :3].T + m[:3, 3]


def union_mesh(vertices, triangles, transforms):
    """The mesh at its own place and at each transform, as one double mesh:
    triangle k of placement j is triangle j * len(triangles) + k."""
    parts = [np.asarray(vertices, np.float64)] + [placed(vertices, m) for m in transforms]
    n = len(vertices)
    tris = np.concatenate([np.asarray(triangles, np.int64) + j * n for j in range(len(parts))])
    return Mesh(np.concatenate(parts), tris)


def random_rays(lo, hi, n, seed):
    rng = np.random.default_rng(seed)
    o = rng.uniform(lo - 1.0, hi + 1.0, (n, 3))
    target = rng.uniform(lo, hi, (n, 3))
    return np.concatenate([o, target - o], axis=1).astype(np.float32)


def instanced_scene(v, f, transforms, **kwargs):
    scene = rtcl.RaycastingScene(**kwargs)
    assert scene.add_triangles(v, f) == 0
    ids = [scene.add_instance(0, m) for m in transforms]
    assert ids == list(range(len(transforms)))
    return scene


def flat_prims(ans, triangle_count):
    """The union mesh's triangle of each answer (-1 on a miss)."""
    placement = np.where(ans["instance_ids"] == INVALID, 0, ans["instance_ids"].astype(np.int64) + 1)
    prims = placement * triangle_count + ans["primitive_ids"].astype(np.int64)
    return np.where(ans["primitive_ids"] == INVALID, -1, prims)


def check_against(scene, mesh, rays, triangle_count):
    ref = RayReference(mesh, with_bounds(rays))
    ans = scene.cast_rays(rays)
    assert ans["instance_ids"].dtype == np.uint32 and ans["instance_ids"].shape == rays.shape[:-1]
    prims = flat_prims(ans, triangle_count)
    bad = ref.judge_closest(ans["t_hit"], prims)
    assert len(bad) == 0, f"{len(bad)} wrong closest hits, e.g. rays {rays[bad[:3]].tolist()}"
    bad = ref.judge_any(scene.test_occlusions(rays))
    assert len(bad) == 0, f"{len(bad)} wrong occlusion answers"
    hit = prims >= 0
    assert np.all(ans["geometry_ids"][hit] == 0) and np.all(ans["geometry_ids"][~hit] == INVALID)
    assert np.all(ans["instance_ids"][~hit] == INVALID)
    # The normal is the placed triangle's unit (v1 - v0) x (v2 - v0).
    n = np.cross(mesh.e1[prims[hit]], mesh.e2[prims[hit]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    assert np.allclose(ans["primitive_normals"][hit], n, atol=1e-5)
    # u, v on the placed triangle give the point at t.
    uv = ans["primitive_uvs"][hit].astype(np.float64)
    p = mesh.a[prims[hit]] + uv[:, :1] * mesh.e1[prims[hit]] + uv[:, 1:] * mesh.e2[prims[hit]]
    r = rays[hit].astype(np.float64)
    assert np.max(np.linalg.norm(p - (r[:, :3] + ans["t_hit"][hit, None] * r[:, 3:]), axis=1)) < 1e-5 * mesh.magnitude
    return ans, ref


@pytest.mark.parametrize("accel", ["bvh", "bvh-packet"])
def test_instances_against_the_brute_force(accel):
    v, f = icosphere(3)
    scene = instanced_scene(v, f, TRANSFORMS, accel=accel)
    mesh = union_mesh(v, f, TRANSFORMS)
    rays = random_rays(mesh.v.min(axis=0), mesh.v.max(axis=0), 3000, seed=11)
    ans, _ = check_against(scene, mesh, rays, len(f))
    # Every placement is hit, the mirrored and the scaled included.
    seen = set(ans["instance_ids"][np.isfinite(ans["t_hit"])].tolist())
    assert seen == {0, 1, 2, INVALID}


def test_instances_answer_as_pre_transformed_copies(bunny_arrays):
    """The bunny placed by the three transforms answers as its copies
    transformed beforehand and added with add_triangles: the same triangles
    hit, t within the scene's tolerance."""
    v, f = bunny_arrays
    transforms = [affine(m[:3, :3], m[:3, 3] * 0.1) for m in TRANSFORMS]
    scene = instanced_scene(v, f, transforms)
    copies = rtcl.RaycastingScene()
    copies.add_triangles(v, f)
    for m in transforms:
        copies.add_triangles(placed(v, m).astype(np.float32), f)
    mesh = union_mesh(v, f, transforms)
    rays = random_rays(mesh.v.min(axis=0), mesh.v.max(axis=0), 2000, seed=5)
    ref = RayReference(mesh, with_bounds(rays))
    ans, other = scene.cast_rays(rays), copies.cast_rays(rays)
    clear = ref.unambiguous()
    assert clear.sum() > 0.75 * len(rays)
    assert np.array_equal(ans["primitive_ids"][clear], other["primitive_ids"][clear])
    copy_of = np.where(ans["instance_ids"] == INVALID, 0, ans["instance_ids"].astype(np.int64) + 1)
    hit = clear & np.isfinite(ans["t_hit"])
    assert hit.sum() > 0.1 * len(rays)
    assert np.array_equal(copy_of[hit], other["geometry_ids"][hit])
    assert np.all(np.abs(ans["t_hit"][hit] - other["t_hit"][hit]) <= 2 * ref.t_tol[hit])
    assert np.array_equal(np.isfinite(ans["t_hit"][clear]), np.isfinite(other["t_hit"][clear]))


def test_set_transform_moves_the_answers():
    v, f = cube_grid(3)
    scene = instanced_scene(v, f, TRANSFORMS[:2])
    rays = random_rays(np.array([-6.0, -6.0, -6.0]), np.array([6.0, 6.0, 6.0]), 2000, seed=3)
    check_against(scene, union_mesh(v, f, TRANSFORMS[:2]), rays, len(f))
    moved = [TRANSFORMS[0], TRANSFORMS[2]]
    scene.set_transform(1, moved[1])
    check_against(scene, union_mesh(v, f, moved), rays, len(f))
    # (3, 4) float32 does the same as (4, 4) float64.
    scene.set_transform(1, TRANSFORMS[1][:3].astype(np.float32))
    check_against(scene, union_mesh(v, f, TRANSFORMS[:2]), rays, len(f))


@pytest.mark.parametrize("with_instance", [False, True])
def test_update_vertices(with_instance):
    """New vertices, answered as the brute force on them: one mesh alone
    (the single-level path) and with an instance (two levels)."""
    v, f = icosphere(2)
    transforms = TRANSFORMS[:1] if with_instance else []
    scene = instanced_scene(v, f, transforms)
    rays = random_rays(np.array([-3.0, -3.0, -3.0]), np.array([4.0, 4.0, 4.0]), 2000, seed=8)
    assert ("instance_ids" in scene.cast_rays(rays)) == with_instance
    wobble = v * (1.0 + 0.3 * np.sin(3.0 * v[:, :1])) + np.array([0.2, -0.1, 0.0])
    scene.update_vertices(0, wobble.astype(np.float64))
    check_against(scene, union_mesh(wobble.astype(np.float32), f, transforms), rays, len(f))
    counts = scene.count_intersections(rays)
    ref = RayReference(union_mesh(wobble.astype(np.float32), f, transforms), with_bounds(rays))
    assert len(ref.judge_count(counts)) == 0


def test_other_queries_through_instances():
    """count_intersections, list_intersections and the point queries of an
    instanced scene (its flattened copy) against the brute force."""
    v, f = icosphere(2)
    scene = instanced_scene(v, f, TRANSFORMS)
    mesh = union_mesh(v, f, TRANSFORMS)
    rays = random_rays(mesh.v.min(axis=0), mesh.v.max(axis=0), 1500, seed=4)
    ref = RayReference(mesh, with_bounds(rays))
    counts = scene.count_intersections(rays)
    assert len(ref.judge_count(counts)) == 0 and counts.max() >= 2
    every = scene.list_intersections(rays)
    splits = every["ray_splits"].astype(np.int64)
    assert np.array_equal(np.diff(splits), counts)
    prims = flat_prims(every, len(f))
    for r in np.nonzero(ref.unambiguous() & (counts > 0))[0][:200]:
        t_ref, tri_ref = ref.crossings(r)
        assert np.allclose(every["t_hit"][splits[r]:splits[r + 1]], t_ref, rtol=0, atol=ref.t_tol[r])
        assert np.array_equal(np.sort(prims[splits[r]:splits[r + 1]]), np.sort(tri_ref))
    points = np.random.default_rng(2).uniform(mesh.v.min(axis=0) - 1, mesh.v.max(axis=0) + 1, (300, 3))
    closest = scene.compute_closest_points(points.astype(np.float32))
    prims = flat_prims(closest, len(f))
    exact = np.min(np.stack([point_triangle_distance(mesh, points, np.full(len(points), t))
                             for t in range(len(mesh.f))]), axis=0)
    tol = 1e-5 * mesh.magnitude
    assert np.allclose(point_triangle_distance(mesh, points, prims), exact, atol=tol)
    assert np.allclose(scene.compute_distance(points), exact, atol=tol)
    # Inside one of the four closed spheres: the origin's and each placement's centre.
    centres = np.stack([np.zeros(3)] + [m[:3, 3] for m in TRANSFORMS])
    far = centres + np.array([0.0, 0.0, 20.0])
    assert np.array_equal(scene.compute_occupancy(np.concatenate([centres, far])), [1.0] * 4 + [0.0] * 4)
    sd = scene.compute_signed_distance(centres)
    assert np.all(sd < 0)


def test_instance_ids_of_misses_and_own_placements():
    v, f = cube_grid(2)
    scene = rtcl.RaycastingScene()
    assert scene.add_triangles(v, f) == 0
    assert scene.add_triangles(v + np.float32(10.0), f) == 1
    plain = scene.cast_rays(np.array([[0, 0, 5, 0, 0, -1]], np.float32))
    assert "instance_ids" not in plain  # as Open3D's until the first instance
    assert scene.add_instance(1, affine(np.eye(3), (-10.0, -10.0, -20.0))) == 0
    assert scene.instance_count == 1
    rays = np.array([[0, 0, 5, 0, 0, -1],        # geometry 0 where add_triangles put it
                     [10, 10, 15, 0, 0, -1],     # geometry 1 where add_triangles put it
                     [0, 0, -5, 0, 0, -1],      # geometry 1's instance, at (0, 0, -10)
                     [50, 50, 50, 1, 0, 0]],     # nothing
                    np.float32)
    ans = scene.cast_rays(rays)
    assert ans["instance_ids"].tolist() == [INVALID, INVALID, 0, INVALID]
    assert ans["geometry_ids"].tolist() == [0, 1, 1, INVALID]
    assert ans["t_hit"].tolist() == [4.0, 4.0, 4.0, np.inf]


def answers(scene, rays):
    ans = scene.cast_rays(rays)
    return {k: a.copy() for k, a in ans.items()}


@pytest.mark.parametrize("call,args,error,words", [
    ("add_instance", (0, np.eye(4)[:, :3]), ValueError, "transform has shape (4, 3)"),
    ("add_instance", (0, np.eye(3)), ValueError, "transform has shape (3, 3)"),
    ("add_instance", (0, np.eye(4, dtype=np.int64)), TypeError, "transform has dtype int64"),
    ("add_instance", (0, affine(np.eye(3), (np.nan, 0, 0))), ValueError, "transform[0, 3] is nan"),
    ("add_instance", (0, affine(np.eye(3), (np.inf, 0, 0))), ValueError, "transform[0, 3] is inf"),
    ("add_instance", (0, np.diag([1.0, 1.0, 1.0, 2.0])), ValueError, "last row"),
    ("add_instance", (0, affine(np.diag([1.0, 0.0, 1.0]), (0, 0, 0))), ValueError, "singular"),
    ("add_instance", (5, np.eye(4)), ValueError, "geometry_id 5 does not exist"),
    ("add_instance", (-1, np.eye(4)), ValueError, "geometry_id is -1"),
    ("set_transform", (7, np.eye(4)), ValueError, "instance_id 7 does not exist"),
    ("set_transform", (0, np.zeros((3, 4))), ValueError, "singular"),
    ("update_vertices", (0, np.zeros((5, 3), np.float32)), ValueError, "vertex_positions has 5 vertices"),
    ("update_vertices", (0, np.full((26, 3), np.nan, np.float32)), ValueError, "update_vertices"),
    ("update_vertices", (0, np.zeros((26, 3), np.float32)), ValueError, "zero area"),
    ("update_vertices", (3, np.zeros((26, 3), np.float32)), ValueError, "geometry_id 3 does not exist"),
    ("update_vertices", (0, np.zeros((26, 2), np.float32)), ValueError, "vertex_positions has shape (26, 2)"),
])
def test_bad_edits_raise_and_change_nothing(call, args, error, words):
    v, f = cube_grid(2)
    assert len(v) == 26
    scene = instanced_scene(v, f, TRANSFORMS[:1])
    rays = random_rays(np.array([-4.0, -4.0, -4.0]), np.array([5.0, 5.0, 5.0]), 500, seed=1)
    before = answers(scene, rays)
    with pytest.raises(error) as e:
        getattr(scene, call)(*args)
    assert words in str(e.value)
    after = answers(scene, rays)
    assert before.keys() == after.keys()
    for k in before:
        assert np.array_equal(before[k], after[k]), k
    assert scene.instance_count == 1


def test_bad_edit_on_a_flat_scene_leaves_it_flat():
    v, f = cube_grid(2)
    scene = rtcl.RaycastingScene(accel="grid")
    scene.add_triangles(v, f)
    rays = random_rays(np.array([-2.0, -2.0, -2.0]), np.array([2.0, 2.0, 2.0]), 200, seed=2)
    before = answers(scene, rays)
    with pytest.raises(ValueError, match="BVH family"):
        scene.add_instance(0, np.eye(4))
    with pytest.raises(ValueError, match="BVH family"):
        scene.update_vertices(0, v)
    after = answers(scene, rays)
    assert "instance_ids" not in after and scene.instance_count == 0
    for k in before:
        assert np.array_equal(before[k], after[k]), k


def test_empty_geometry_and_instances_added_later():
    """An empty geometry's instances hit nothing; a geometry added after the
    scene became instanced is seen where add_triangles put it."""
    v, f = cube_grid(2)
    scene = rtcl.RaycastingScene()
    empty = scene.add_triangles(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32))
    assert scene.add_instance(empty, np.eye(4)) == 0
    rays = np.array([[0, 0, 5, 0, 0, -1], [0, 0, -5, 0, 0, -1]], np.float32)
    assert scene.cast_rays(rays)["t_hit"].tolist() == [np.inf, np.inf]
    cube = scene.add_triangles(v, f)
    assert scene.add_instance(cube, affine(np.eye(3), (0.0, 0.0, -10.0))) == 1
    ans = scene.cast_rays(rays)
    assert ans["t_hit"].tolist() == [4.0, 4.0]
    assert ans["instance_ids"].tolist() == [INVALID, 1]
    assert ans["geometry_ids"].tolist() == [cube, cube]


def test_edits_and_queries_from_several_threads():
    """Queries while another thread moves an instance back and forth: each
    answer is that of one of the two placements, never a mix or a crash."""
    v, f = cube_grid(2)
    scene = instanced_scene(v, f, [affine(np.eye(3), (0.0, 0.0, -10.0))])
    rays = np.array([[0, 0, -5, 0, 0, -1]] * 1000, np.float32)  # hits the instance only
    places = [affine(np.eye(3), (0.0, 0.0, -10.0)), affine(np.eye(3), (0.0, 0.0, -20.0))]
    stop = threading.Event()
    seen, errors = set(), []

    def query():
        try:
            while not stop.is_set():
                t = scene.cast_rays(rays)["t_hit"]
                assert len(set(t.tolist())) == 1, "one call saw two placements"
                seen.add(float(t[0]))
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=query) for _ in range(3)]
    for t in threads:
        t.start()
    for k in range(30):
        scene.set_transform(0, places[k % 2])
    stop.set()
    for t in threads:
        t.join()
    assert not errors, errors[0]
    assert seen <= {4.0, 14.0} and seen


def test_a_mesh_with_nothing_to_hit_gains_area():
    """A mesh of one zero-area triangle, placed twice, is never hit; moved by
    update_vertices to a real triangle, both placements are."""
    flat = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], np.float32)
    scene = rtcl.RaycastingScene()
    g = scene.add_triangles(flat, np.array([[0, 1, 2]], np.uint32))
    assert scene.add_instance(g, affine(np.eye(3), (0.0, 0.0, -10.0))) == 0
    rays = np.array([[0.2, 0.2, 5, 0, 0, -1], [0.2, 0.2, -5, 0, 0, -1]], np.float32)
    assert scene.cast_rays(rays)["t_hit"].tolist() == [np.inf, np.inf]
    scene.update_vertices(g, np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32))
    ans = scene.cast_rays(rays)
    assert np.allclose(ans["t_hit"], [5.0, 5.0], rtol=0, atol=1e-5)
    assert ans["instance_ids"].tolist() == [INVALID, 0]
    assert np.allclose(ans["primitive_normals"], [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]], atol=1e-6)
