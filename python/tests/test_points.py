"""Point queries: distances and closest points against Open3D's
compute_distance / compute_closest_points (which work on Debian 12's
Open3D 0.16, unlike its ray queries) and a double-precision distance to the
reported triangle; signed distance and occupancy against known inside and
outside points of closed meshes (closed forms, the winding number)."""
import numpy as np
import pytest

import rtcl
from meshes import cube_grid, icosphere
from reference import Mesh, point_triangle_distance, winding_numbers

INVALID = rtcl.RaycastingScene.INVALID_ID


def box_points(vertices, count, grow=0.1, seed=5):
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    pad = grow * (hi - lo)
    return np.random.default_rng(seed).uniform(lo - pad, hi + pad, (count, 3)).astype(np.float32)


def test_distance_and_closest_points_against_open3d(o3d, bunny_arrays, bunny_mesh):
    v, f = bunny_arrays
    points = box_points(v, 3000)
    ref_scene = o3d.t.geometry.RaycastingScene()
    ref_scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f))
    ref_d = ref_scene.compute_distance(o3d.core.Tensor(points)).numpy()
    ref_c = {k: x.numpy() for k, x in ref_scene.compute_closest_points(o3d.core.Tensor(points)).items()}

    scene = rtcl.RaycastingScene()
    scene.add_triangles(v, f)
    d = scene.compute_distance(points)
    c = scene.compute_closest_points(points)
    tol = 1e-5 * bunny_mesh.magnitude  # Open3D computes in float, too
    assert d.dtype == np.float32 and d.shape == (len(points),)
    assert np.max(np.abs(d - ref_d)) < tol
    assert set(c) == {"points", "geometry_ids", "primitive_ids", "primitive_uvs", "primitive_normals"}
    for key, value in c.items():
        assert value.shape == ref_c[key].shape and value.dtype == ref_c[key].dtype, key
    assert np.all(c["geometry_ids"] == 0)
    # The reported triangle is at the reported distance (double precision);
    # where Open3D reports another one, that is a tie: the point's nearest
    # feature is a vertex or an edge of several triangles.
    prims = c["primitive_ids"].astype(np.int64)
    exact = point_triangle_distance(bunny_mesh, points, prims)
    assert np.max(np.abs(exact - d)) < tol
    theirs = point_triangle_distance(bunny_mesh, points, ref_c["primitive_ids"].astype(np.int64))
    assert np.max(np.abs(theirs - exact)) < tol
    # Both points are at that distance (where they differ, the query point is
    # as far from both).
    for closest in (c["points"], ref_c["points"]):
        assert np.max(np.abs(np.linalg.norm(closest.astype(np.float64) - points, axis=1) - exact)) < tol
    uv = c["primitive_uvs"].astype(np.float64)
    m = bunny_mesh
    from_uv = m.a[prims] + uv[:, :1] * m.e1[prims] + uv[:, 1:] * m.e2[prims]
    assert np.max(np.linalg.norm(from_uv - c["points"], axis=1)) < tol
    same = c["primitive_ids"] == ref_c["primitive_ids"]
    assert np.allclose(c["primitive_normals"][same], ref_c["primitive_normals"][same], atol=1e-5)
    assert np.allclose(c["primitive_uvs"][same], ref_c["primitive_uvs"][same], atol=1e-3)


def test_closest_points_of_several_meshes_against_open3d(o3d):
    v, f = icosphere(2)
    parts = [(v, f), (v + np.float32(3.0), f), (0.5 * v - np.float32(2.0), f)]
    ref_scene = o3d.t.geometry.RaycastingScene()
    scene = rtcl.RaycastingScene()
    for pv, pf in parts:
        assert scene.add_triangles(pv, pf) == ref_scene.add_triangles(o3d.core.Tensor(pv), o3d.core.Tensor(pf))
    points = np.random.default_rng(11).uniform(-4.0, 6.0, (2000, 3)).astype(np.float32)
    ref = {k: x.numpy() for k, x in ref_scene.compute_closest_points(o3d.core.Tensor(points)).items()}
    ours = scene.compute_closest_points(points)
    assert np.array_equal(ours["geometry_ids"], ref["geometry_ids"])
    d_ref = ref_scene.compute_distance(o3d.core.Tensor(points)).numpy()
    d = scene.compute_distance(points)
    assert np.max(np.abs(d - d_ref)) < 1e-5
    # The reported triangle of the reported mesh is at that distance.
    merged = Mesh(np.concatenate([pv for pv, _ in parts]),
                  np.concatenate([pf.astype(np.int64) + k * len(v) for k, (_, pf) in enumerate(parts)]))
    prims = ours["geometry_ids"].astype(np.int64) * len(f) + ours["primitive_ids"]
    assert np.max(np.abs(point_triangle_distance(merged, points, prims) - d)) < 1e-5
    assert np.max(np.abs(np.linalg.norm(ours["points"] - points, axis=1) - d)) < 1e-5


def cube_distance(p):
    """Signed distance to the cube [-1, 1]^3 (closed form)."""
    q = np.abs(p) - 1.0
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(np.max(q, axis=1), 0.0)
    return outside + inside


@pytest.mark.parametrize("nsamples", [1, 3])
def test_signed_distance_and_occupancy_of_the_cube(nsamples):
    scene = rtcl.RaycastingScene()
    scene.add_triangles(*cube_grid(4))
    p = np.random.default_rng(2).uniform(-2.0, 2.0, (3000, 3))
    exact = cube_distance(p)
    clear = np.abs(exact) > 1e-3
    sd = scene.compute_signed_distance(p.astype(np.float32), nsamples=nsamples)
    assert sd.dtype == np.float32
    assert np.max(np.abs(sd[clear] - exact[clear])) < 1e-5
    occ = scene.compute_occupancy(p.astype(np.float32), nsamples=nsamples)
    assert occ.dtype == np.float32
    assert np.array_equal(occ[clear], (exact[clear] < 0).astype(np.float32))
    # Points on the axes and diagonals: rays from them meet edges and vertices.
    axes = np.array([[0, 0, 0], [0.5, 0, 0], [0, 0.5, 0.5], [0.5, 0.5, 0.5], [1.5, 0, 0], [1.5, 1.5, 1.5]],
                    np.float32)
    assert np.array_equal(scene.compute_occupancy(axes, nsamples=nsamples), [1, 1, 1, 1, 0, 0])


def test_signed_distance_of_the_icosphere():
    v, f = icosphere(3)
    scene = rtcl.RaycastingScene()
    scene.add_triangles(v, f)
    rng = np.random.default_rng(4)
    directions = rng.normal(size=(2000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    radii = np.concatenate([rng.uniform(0.0, 0.95, 1000), rng.uniform(1.05, 2.0, 1000)])
    p = (directions * radii[:, None]).astype(np.float32)
    sd = scene.compute_signed_distance(p, nsamples=3)
    assert np.all((sd < 0) == (radii < 1.0))
    # Distance within the polyhedron's deviation from the sphere (< 0.5% at level 3).
    assert np.max(np.abs(np.abs(sd) - np.abs(radii - 1.0))) < 5e-3
    assert np.array_equal(scene.compute_occupancy(p), (radii < 1.0).astype(np.float32))


def test_occupancy_of_the_dragon(o3d, dragon_arrays):
    """Points in the dragon's box at least 1e-4 of its diagonal from the
    surface, inside or outside by the winding number (double precision);
    the signed distance's magnitude against Open3D's compute_distance."""
    v, f = dragon_arrays
    mesh = Mesh(v, f)
    scene = rtcl.RaycastingScene()
    scene.add_triangles(v, f)
    p = box_points(v, 400, grow=0.05, seed=8)
    ref_scene = o3d.t.geometry.RaycastingScene()
    ref_scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f))
    d = ref_scene.compute_distance(o3d.core.Tensor(p)).numpy()
    far = d > 1e-4 * np.linalg.norm(v.max(axis=0) - v.min(axis=0))
    p = p[far]
    w = winding_numbers(mesh, p)
    assert np.all((np.abs(w) < 1e-3) | (np.abs(w - 1.0) < 1e-3)), "the dragon should be closed"
    inside = w > 0.5
    assert 10 < inside.sum() < len(p) - 10  # both kinds are tested
    occ = scene.compute_occupancy(p, nsamples=3)
    assert np.array_equal(occ, inside.astype(np.float32))
    sd = scene.compute_signed_distance(p)
    assert np.array_equal(sd < 0, inside)
    # Open3D computes in float, too: within 1e-5 of the dragon's magnitude.
    assert np.max(np.abs(np.abs(sd) - d[far])) < 1e-5 * mesh.magnitude


def test_empty_scene_answers_misses():
    scene = rtcl.RaycastingScene()
    p = np.zeros((4, 3), np.float32)
    assert np.all(scene.compute_distance(p) == np.inf)
    assert np.all(scene.compute_signed_distance(p) == np.inf)
    assert np.all(scene.compute_occupancy(p) == 0)
    c = scene.compute_closest_points(p)
    assert np.all(np.isnan(c["points"])) and np.all(c["primitive_ids"] == INVALID)
    rays = np.array([[0, 0, 0, 0, 0, 1]], np.float32)
    ans = scene.cast_rays(rays)
    assert ans["t_hit"][0] == np.inf and ans["geometry_ids"][0] == INVALID
    assert not scene.test_occlusions(rays)[0] and scene.count_intersections(rays)[0] == 0
    assert scene.list_intersections(rays)["ray_splits"].tolist() == [0, 0]
