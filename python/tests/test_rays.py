"""Ray queries (cast_rays, test_occlusions, count_intersections,
list_intersections) against the double-precision brute force and closed
forms: the bunny's camera and diffuse rays, closed adversarial meshes."""
import numpy as np
import pytest

import rtcl
from meshes import cube_grid, icosphere, open_edges
from reference import Mesh, RayReference
from conftest import with_bounds

INVALID = rtcl.RaycastingScene.INVALID_ID


def prims_of(answer):
    p = answer["primitive_ids"].astype(np.int64)
    p[answer["primitive_ids"] == INVALID] = -1
    return p


def failures(ids, rays, answer_text):
    return f"{len(ids)} wrong, e.g. rays {rays[ids[:3]].tolist()} ({answer_text})"


@pytest.mark.parametrize("which", ["camera", "diffuse"])
@pytest.mark.parametrize("coherent", [False, True])
def test_bunny_closest_hit(bunny_scene, bunny_camera, bunny_diffuse, which, coherent):
    rays, ref = bunny_camera if which == "camera" else bunny_diffuse
    ans = bunny_scene.cast_rays(rays, coherent=coherent)
    assert ans["t_hit"].shape == rays.shape[:-1] and ans["t_hit"].dtype == np.float32
    assert ans["primitive_uvs"].shape == rays.shape[:-1] + (2,)
    assert ans["primitive_normals"].shape == rays.shape[:-1] + (3,)
    t = ans["t_hit"].reshape(-1)
    prims = prims_of(ans).reshape(-1)
    bad = ref.judge_closest(t, prims)
    assert len(bad) == 0, failures(bad, rays.reshape(-1, 6), "closest")
    hits = np.isfinite(t)
    assert hits.sum() > (0.3 if which == "camera" else 0.1) * len(t)  # the rays do meet the bunny
    assert np.all(ans["geometry_ids"].reshape(-1)[hits] == 0)
    assert np.all(ans["geometry_ids"].reshape(-1)[~hits] == INVALID)
    # The hit point from (u, v) on the reported triangle is the point at t.
    mesh = ref.mesh
    uv = ans["primitive_uvs"].reshape(-1, 2)[hits].astype(np.float64)
    p = prims[hits]
    from_uv = mesh.a[p] + uv[:, :1] * mesh.e1[p] + uv[:, 1:] * mesh.e2[p]
    flat = rays.reshape(-1, 6)[hits].astype(np.float64)
    on_ray = flat[:, :3] + t[hits, None] * flat[:, 3:]
    assert np.max(np.linalg.norm(from_uv - on_ray, axis=1)) < 1e-5 * mesh.magnitude
    n = np.cross(mesh.e1[p], mesh.e2[p])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    assert np.allclose(ans["primitive_normals"].reshape(-1, 3)[hits], n, atol=1e-5)


@pytest.mark.parametrize("which", ["camera", "diffuse"])
def test_bunny_occlusion_and_counts(bunny_scene, bunny_camera, bunny_diffuse, which):
    rays, ref = bunny_camera if which == "camera" else bunny_diffuse
    flat = rays.reshape(-1, 6)
    for coherent in (False, True):  # camera rays keep the promise, diffuse rays break it (still right)
        occluded = bunny_scene.test_occlusions(rays, coherent=coherent)
        assert occluded.dtype == np.bool_ and occluded.shape == rays.shape[:-1]
        bad = ref.judge_any(occluded.reshape(-1))
        assert len(bad) == 0, failures(bad, flat, f"occlusion, coherent={coherent}")
        assert occluded.sum() > (0.3 if which == "camera" else 0.02) * occluded.size
    counts = bunny_scene.count_intersections(rays)
    assert counts.dtype == np.int32 and counts.shape == rays.shape[:-1]
    bad = ref.judge_count(counts.reshape(-1))
    assert len(bad) == 0, failures(bad, flat, "count")
    assert counts.max() >= 2  # rays that cross the bunny more than once


def test_bunny_every_hit(bunny_scene, bunny_camera):
    rays, ref = bunny_camera
    flat = rays.reshape(-1, 6)
    ans = bunny_scene.list_intersections(rays)
    splits = ans["ray_splits"]
    assert splits.dtype == np.uint32 and splits.shape == (len(flat) + 1,) and splits[0] == 0
    assert np.all(np.diff(splits.astype(np.int64)) >= 0)
    assert np.array_equal(ans["ray_ids"], np.repeat(np.arange(len(flat)), np.diff(splits.astype(np.int64))))
    counts = bunny_scene.count_intersections(rays).reshape(-1)
    assert np.array_equal(np.diff(splits.astype(np.int64)), counts)
    checked = 0
    for r in np.nonzero(ref.unambiguous())[0]:
        t_ref, tri_ref = ref.crossings(r)
        lo, hi = splits[r], splits[r + 1]
        assert hi - lo == len(t_ref), f"ray {r}: {hi - lo} crossings, reference {len(t_ref)}"
        assert np.all(np.diff(ans["t_hit"][lo:hi]) >= 0)
        assert np.allclose(ans["t_hit"][lo:hi], t_ref, rtol=0, atol=ref.t_tol[r])
        assert np.array_equal(np.sort(ans["primitive_ids"][lo:hi]), np.sort(tri_ref))
        checked += len(t_ref)
    assert checked > 500
    assert np.all(ans["geometry_ids"] == 0)
    assert ans["primitive_uvs"].shape == (splits[-1], 2)


def closed_scene(mesh):
    scene = rtcl.RaycastingScene()
    scene.add_triangles(*mesh)
    return scene


@pytest.mark.parametrize("name,mesh", [("cube", cube_grid(4)), ("icosphere", icosphere(2))])
def test_closed_meshes_are_closed(name, mesh):
    assert open_edges(mesh[1]) == 0, name
    m = Mesh(*mesh)
    volume = np.sum(np.einsum("ij,ij->i", m.a, np.cross(m.e1, m.e2))) / 6.0
    assert volume > 0, f"{name} is wound inwards"


def test_cube_axis_parallel_rays_through_edges_and_vertices():
    """Rays along the axes through the grid's vertices and edges (shared by
    2 to 6 triangles): each enters and leaves once (t = 4 and 6 from 5
    units out); from the centre each crosses once."""
    v, f = cube_grid(4)
    scene = closed_scene((v, f))
    grid = np.linspace(-1.0, 1.0, 9)[1:-1]  # vertices at multiples of 0.5, edge midpoints between
    xs, ys = np.meshgrid(grid, grid)
    rays = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            o = np.zeros((xs.size, 3))
            o[:, (axis + 1) % 3], o[:, (axis + 2) % 3] = xs.ravel(), ys.ravel()
            o[:, axis] = 5.0 * sign
            d = np.zeros_like(o)
            d[:, axis] = -sign
            rays.append(np.concatenate([o, d], axis=1))
    rays = np.concatenate(rays).astype(np.float32)
    ans = scene.cast_rays(rays)
    assert np.all(ans["t_hit"] == 4.0)
    assert np.all(scene.test_occlusions(rays))
    assert np.all(scene.count_intersections(rays) == 2)
    every = scene.list_intersections(rays)
    assert np.all(np.diff(every["ray_splits"].astype(np.int64)) == 2)
    assert np.array_equal(every["t_hit"].reshape(-1, 2), np.tile([4.0, 6.0], (len(rays), 1)))
    # From inside, along the same lines.
    inner = rays.copy()
    inner[:, :3] = np.where(rays[:, 3:] != 0, 0.0, rays[:, :3])
    assert np.all(scene.count_intersections(inner) == 1)
    assert np.all(scene.cast_rays(inner)["t_hit"] == 1.0)
    # Normals are the faces' outward axes.
    n = ans["primitive_normals"]
    assert np.array_equal(n, -rays[:, 3:])


def test_icosphere_rays_through_vertices():
    """From the centre through every vertex (shared by 5 or 6 triangles):
    one crossing at t = 1 (the vertex lies on the unit sphere); from outside
    through the centre and a vertex: two crossings."""
    v, f = icosphere(2)
    scene = closed_scene((v, f))
    d = v.astype(np.float64)
    rays = np.concatenate([np.zeros_like(d), d], axis=1).astype(np.float32)
    assert np.all(scene.count_intersections(rays) == 1)
    t = scene.cast_rays(rays)["t_hit"]
    assert np.allclose(t, 1.0, atol=1e-6)
    outside = np.concatenate([-3.0 * d, d], axis=1).astype(np.float32)
    assert np.all(scene.count_intersections(outside) == 2)
    assert np.allclose(scene.cast_rays(outside)["t_hit"], 2.0, atol=1e-6)


def test_icosphere_random_rays_against_reference():
    v, f = icosphere(3)
    scene = closed_scene((v, f))
    rng = np.random.default_rng(7)
    n = 2000
    o = rng.uniform(-2.0, 2.0, (n, 3))
    d = rng.normal(size=(n, 3))
    rays = np.concatenate([o, d], axis=1).astype(np.float32)
    ref = RayReference(Mesh(v, f), with_bounds(rays))
    ans = scene.cast_rays(rays)
    assert len(ref.judge_closest(ans["t_hit"], prims_of(ans))) == 0
    assert len(ref.judge_any(scene.test_occlusions(rays))) == 0
    counts = scene.count_intersections(rays)
    assert len(ref.judge_count(counts)) == 0
    inside = np.linalg.norm(o, axis=1) < 0.95
    assert np.all(counts[inside] == 1)


def test_tnear_tfar():
    scene = closed_scene(cube_grid(2))
    rays = np.array([[0.1, 0.2, 5.0, 0.0, 0.0, -1.0]] * 1, np.float32)
    assert scene.cast_rays(rays, tnear=4.5)["t_hit"][0] == 6.0
    assert scene.cast_rays(rays, tfar=3.9)["t_hit"][0] == np.inf
    assert scene.cast_rays(rays, tnear=4.0, tfar=4.0)["t_hit"][0] == 4.0
    assert not scene.test_occlusions(rays, tnear=6.5)[0]
    assert scene.test_occlusions(rays, 0.0, 4.0)[0]
    assert not scene.test_occlusions(rays, 0.0, 3.99)[0]


def test_several_meshes_report_their_ids():
    """Two cubes (the second moved by +4 in x) and an empty mesh between
    them: each hit names its mesh and its triangle within that mesh."""
    v, f = cube_grid(2)
    scene = rtcl.RaycastingScene()
    assert scene.add_triangles(v, f) == 0
    assert scene.add_triangles(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32)) == 1
    moved = v + np.array([4.0, 0.0, 0.0], np.float32)
    assert scene.add_triangles(moved, f) == 2
    assert scene.geometry_count == 3
    rng = np.random.default_rng(3)
    xy = rng.uniform(-0.9, 0.9, (200, 2))
    shift = np.where(np.arange(200) % 2 == 0, 0.0, 4.0)
    rays = np.stack([xy[:, 0] + shift, xy[:, 1], np.full(200, 5.0), np.zeros(200), np.zeros(200),
                     -np.ones(200)], axis=1).astype(np.float32)
    ans = scene.cast_rays(rays)
    assert np.all(ans["t_hit"] == 4.0)
    assert np.array_equal(ans["geometry_ids"], np.where(shift == 0.0, 0, 2).astype(np.uint32))
    # The reported triangle of the reported mesh holds the hit point.
    for i in range(200):
        verts = (v if shift[i] == 0.0 else moved).astype(np.float64)
        a, b, c = verts[f[ans["primitive_ids"][i]]]
        u, w = ans["primitive_uvs"][i]
        p = (1 - u - w) * a + u * b + w * c
        assert np.allclose(p, [rays[i, 0], rays[i, 1], 1.0], atol=1e-6)
    every = scene.list_intersections(rays)
    assert np.array_equal(every["geometry_ids"][::2], ans["geometry_ids"])
    counts = scene.count_intersections(rays)
    assert np.all(counts == 2)
    # A change after queries is seen by the next query.
    scene.add_triangles(v + np.array([0.0, 0.0, 3.0], np.float32), f)
    again = scene.cast_rays(rays)
    assert np.all(again["t_hit"][shift == 0.0] == 1.0)
    assert np.all(again["geometry_ids"][shift == 0.0] == 3)


def test_every_hit_of_two_meshes_against_reference():
    """list_intersections on a scene of two meshes (an icosphere, and a cube
    behind it that the same rays cross): each crossing's geometry_ids,
    primitive_ids, t_hit and primitive_uvs against the double-precision
    brute force on the two meshes as one, where the ray is unambiguous."""
    sphere, cube = icosphere(2), cube_grid(3)
    cube = (cube[0] * np.float32(0.8) + np.array([3.0, 0.2, -0.1], np.float32), cube[1])
    scene = rtcl.RaycastingScene()
    assert scene.add_triangles(*sphere) == 0
    assert scene.add_triangles(*cube) == 1
    merged = Mesh(np.concatenate([sphere[0], cube[0]]),
                  np.concatenate([sphere[1].astype(np.int64), cube[1].astype(np.int64) + len(sphere[0])]))
    first_of = np.array([0, len(sphere[1])])  # merged triangle = first_of[geometry] + primitive
    rng = np.random.default_rng(12)
    n = 600
    o = np.stack([np.full(n, -4.0), rng.uniform(-1.2, 1.2, n), rng.uniform(-1.2, 1.2, n)], axis=1)
    target = np.stack([np.full(n, 5.0), rng.uniform(-1.0, 1.4, n), rng.uniform(-1.3, 1.1, n)], axis=1)
    rays = np.concatenate([o, target - o], axis=1).astype(np.float32)
    ref = RayReference(merged, with_bounds(rays))
    every = scene.list_intersections(rays)
    splits = every["ray_splits"].astype(np.int64)
    assert every["geometry_ids"].dtype == np.uint32 and every["primitive_uvs"].dtype == np.float32
    seen = set()
    checked = 0
    for r in np.nonzero(ref.unambiguous())[0]:
        t_ref, tri_ref = ref.crossings(r)
        lo, hi = splits[r], splits[r + 1]
        assert hi - lo == len(t_ref), f"ray {r}: {hi - lo} crossings, reference {len(t_ref)}"
        g = every["geometry_ids"][lo:hi].astype(np.int64)
        assert np.all(g <= 1)
        tri = first_of[g] + every["primitive_ids"][lo:hi]
        # Sorted by t, the same triangles as the reference (a hit's t and
        # uv are checked on its own triangle, so equal t in any order).
        assert np.array_equal(np.sort(tri), np.sort(tri_ref)), f"ray {r}"
        assert np.allclose(every["t_hit"][lo:hi], t_ref, rtol=0, atol=ref.t_tol[r])
        o_r = np.repeat(ref.rays[r:r + 1, :3], hi - lo, axis=0)
        d_r = np.repeat(ref.rays[r:r + 1, 3:6], hi - lo, axis=0)
        u_ref, v_ref = merged.pair_uvs(o_r, d_r, tri)
        uv = every["primitive_uvs"][lo:hi].astype(np.float64)
        assert np.allclose(uv[:, 0], u_ref, atol=1e-5) and np.allclose(uv[:, 1], v_ref, atol=1e-5), f"ray {r}"
        seen.update(g.tolist())
        checked += hi - lo
    assert seen == {0, 1} and checked > 1000
