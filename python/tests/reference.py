"""Double-precision brute force for the ray and point queries, independent of
rtcl. Tolerances scale with the scene: 256 float ulps of the largest of the
scene's extent, its corners' and the ray origin's magnitudes. A hit is
"clear" when the ray passes inside its triangle by more than that distance,
and "ambiguous" within it, where either answer is right."""
import numpy as np

FLT_EPS = np.finfo(np.float32).eps


class Mesh:
    """A triangle mesh in double precision with what the references need."""

    def __init__(self, vertices, triangles):
        self.v = np.asarray(vertices, np.float64)
        self.f = np.asarray(triangles, np.int64)
        a, b, c = (self.v[self.f[:, k]] for k in range(3))
        self.a, self.e1, self.e2 = a, b - a, c - a
        n = np.cross(self.e1, self.e2)
        area2 = np.linalg.norm(n, axis=1)
        self.valid = area2 > 0  # zero-area triangles are never hit
        with np.errstate(divide="ignore", invalid="ignore"):
            # Heights over the edge opposite each corner (a, b, c): the
            # distance of a point inside to that edge's line is its
            # barycentric coordinate of the corner times the height.
            self.heights = np.stack([area2 / np.linalg.norm(c - b, axis=1),
                                     area2 / np.linalg.norm(c - a, axis=1),
                                     area2 / np.linalg.norm(b - a, axis=1)], axis=1)
        self.centre = (a + b + c) / 3.0
        self.radius = np.max(np.stack([np.linalg.norm(p - self.centre, axis=1) for p in (a, b, c)]), axis=0)
        lo, hi = self.v.min(axis=0), self.v.max(axis=0)
        self.magnitude = max(np.linalg.norm(hi - lo), np.linalg.norm(lo), np.linalg.norm(hi))

    def tolerance(self, origins, directions, ulps=256.0):
        """Spatial tolerance (scene units) and t tolerance of each ray."""
        space = ulps * FLT_EPS * np.maximum(self.magnitude, np.linalg.norm(origins, axis=1))
        return space, space / np.linalg.norm(directions, axis=1)

    def pair_hits(self, o, d, prims):
        """The plane hit of ray (o[i], d[i]) with triangle prims[i]: t and the
        signed distance of the plane point to the triangle's boundary
        (> 0 inside); NaN t where the ray is parallel to the plane."""
        e1, e2, a = self.e1[prims], self.e2[prims], self.a[prims]
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - a
            u = np.einsum("ij,ij->i", s, p) * inv
            q = np.cross(s, e1)
            v = np.einsum("ij,ij->i", d, q) * inv
            t = np.einsum("ij,ij->i", e2, q) * inv
            bary = np.stack([1.0 - u - v, u, v], axis=1)
            margin = np.min(bary * self.heights[prims], axis=1)
        bad = (det == 0) | ~self.valid[prims] | ~np.isfinite(t)
        t[bad] = np.nan
        margin[bad] = -np.inf
        return t, margin

    def pair_uvs(self, o, d, prims):
        """The barycentric (u, v) of the plane hit of ray (o[i], d[i]) with
        triangle prims[i]: the point is (1 - u - v) a + u b + v c."""
        e1, e2, a = self.e1[prims], self.e2[prims], self.a[prims]
        p = np.cross(d, e2)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / np.einsum("ij,ij->i", e1, p)
            s = o - a
            u = np.einsum("ij,ij->i", s, p) * inv
            v = np.einsum("ij,ij->i", d, np.cross(s, e1)) * inv
        return u, v

    def candidates(self, origins, directions, chunk=64):
        """(ray, triangle) pairs whose triangle's bounding sphere the ray's
        line passes within a tolerance of: a superset of every hit."""
        rays, tris = [], []
        c, r = self.centre, self.radius * (1.0 + 1e-6) + 1e-6 * self.magnitude
        cc = np.einsum("ij,ij->i", c, c)
        for s in range(0, len(origins), chunk):
            o = origins[s:s + chunk]
            d = directions[s:s + chunk] / np.linalg.norm(directions[s:s + chunk], axis=1)[:, None]
            co = c @ o.T
            cd = c @ d.T
            od = np.einsum("ij,ij->i", o, d)
            oo = np.einsum("ij,ij->i", o, o)
            along = cd - od[None, :]
            dist2 = cc[:, None] - 2.0 * co + oo[None, :] - along * along
            slack = 1e-9 * (cc[:, None] + oo[None, :]) + (2 * r * r)[:, None] * 1e-6
            tri, ray = np.nonzero(dist2 <= (r * r)[:, None] + slack)
            rays.append(ray + s)
            tris.append(tri)
        return np.concatenate(rays), np.concatenate(tris)


class RayReference:
    """Every plane hit of every ray near its triangle, in double precision.
    rays: (n, 8) ox oy oz dx dy dz tmin tmax."""

    def __init__(self, mesh, rays):
        self.mesh = mesh
        self.rays = np.asarray(rays, np.float64)
        o, d = self.rays[:, :3], self.rays[:, 3:6]
        self.space, self.t_tol = mesh.tolerance(o, d)
        ray, tri = mesh.candidates(o, d)
        t, margin = mesh.pair_hits(o[ray], d[ray], tri)
        tmin, tmax, tol, tt = self.rays[ray, 6], self.rays[ray, 7], self.space[ray], self.t_tol[ray]
        near = np.isfinite(t) & (margin >= -tol)
        self.ray, self.tri, self.t, self.margin = ray[near], tri[near], t[near], margin[near]
        tmin, tmax, tol, tt = tmin[near], tmax[near], tol[near], tt[near]
        self.clear = (self.margin > tol) & (self.t > tmin + tt) & (self.t < tmax - tt)
        # Near the boundary of the triangle or of [tmin, tmax]: either way.
        self.ambiguous = ~self.clear & (self.t >= tmin - tt) & (self.t <= tmax + tt)
        n = len(self.rays)
        self.closest_t = np.full(n, np.inf)
        np.minimum.at(self.closest_t, self.ray[self.clear], self.t[self.clear])
        self.clear_count = np.bincount(self.ray[self.clear], minlength=n)
        self.ambiguous_count = np.bincount(self.ray[self.ambiguous], minlength=n)

    def judge_closest(self, t_hit, prims):
        """Indices of the rays whose answer (t, triangle; inf and -1 on a
        miss) is wrong: a hit must lie on its triangle (within tolerance) at
        its t, and no clear hit may be nearer; a miss needs no clear hit."""
        n = len(self.rays)
        t_hit = np.asarray(t_hit, np.float64)
        hit = prims >= 0
        wrong = np.zeros(n, bool)
        wrong[~hit] = np.isfinite(self.closest_t[~hit]) | np.isfinite(t_hit[~hit])
        idx = np.nonzero(hit)[0]
        if len(idx):
            o, d = self.rays[idx, :3], self.rays[idx, 3:6]
            t, margin = self.mesh.pair_hits(o, d, prims[idx])
            tt, tol = self.t_tol[idx], self.space[idx]
            on = np.isfinite(t) & (margin >= -tol) & (np.abs(t - t_hit[idx]) <= tt)
            inside = (t_hit[idx] >= self.rays[idx, 6] - tt) & (t_hit[idx] <= self.rays[idx, 7] + tt)
            nearest = t_hit[idx] <= self.closest_t[idx] + tt
            wrong[idx] = ~(on & inside & nearest)
        return np.nonzero(wrong)[0]

    def judge_any(self, occluded):
        """Rays whose occlusion answer is wrong: blocked needs a hit (clear or
        ambiguous), free needs no clear one."""
        some = (self.clear_count + self.ambiguous_count) > 0
        wrong = np.where(occluded, ~some, self.clear_count > 0)
        return np.nonzero(wrong)[0]

    def judge_count(self, counts):
        """Rays whose crossing count lies outside [clear, clear + ambiguous]."""
        counts = np.asarray(counts)
        wrong = (counts < self.clear_count) | (counts > self.clear_count + self.ambiguous_count)
        return np.nonzero(wrong)[0]

    def unambiguous(self):
        return self.ambiguous_count == 0

    def crossings(self, ray):
        """The clear hits of one ray as (t, triangle), sorted by t."""
        sel = (self.ray == ray) & self.clear
        order = np.lexsort((self.tri[sel], self.t[sel]))
        return self.t[sel][order], self.tri[sel][order]


def winding_numbers(mesh, points):
    """The generalised winding number of a closed mesh at each point (1 inside,
    0 outside), by the solid angles of its triangles (Van Oosterom and
    Strackee 1983), in double precision."""
    out = np.empty(len(points))
    a0, b0, c0 = (mesh.v[mesh.f[:, k]] for k in range(3))
    for i, p in enumerate(np.asarray(points, np.float64)):
        a, b, c = a0 - p, b0 - p, c0 - p
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la
               + np.einsum("ij,ij->i", c, a) * lb)
        out[i] = np.sum(np.arctan2(det, den)) / (2.0 * np.pi)
    return out


def point_triangle_distance(mesh, points, prims):
    """Distance of each point to triangle prims[i] (double; Ericson 5.1.5)."""
    p = np.asarray(points, np.float64)
    a, ab, ac = mesh.a[prims], mesh.e1[prims], mesh.e2[prims]
    # Closest point by projection onto the plane and clamping to the edges:
    # the minimum over the interior projection and the three segments.
    def seg(p, s, e):
        d = e - s
        with np.errstate(invalid="ignore", divide="ignore"):
            w = np.clip(np.einsum("ij,ij->i", p - s, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
        w = np.nan_to_num(w)
        return np.linalg.norm(p - (s + w[:, None] * d), axis=1)
    b, c = a + ab, a + ac
    best = np.minimum(np.minimum(seg(p, a, b), seg(p, b, c)), seg(p, c, a))
    n = np.cross(ab, ac)
    nn = np.einsum("ij,ij->i", n, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        h = np.einsum("ij,ij->i", p - a, n) / nn
        q = p - h[:, None] * n
        # Inside test of the projection by edge signs.
        s0 = np.einsum("ij,ij->i", np.cross(b - a, q - a), n)
        s1 = np.einsum("ij,ij->i", np.cross(c - b, q - b), n)
        s2 = np.einsum("ij,ij->i", np.cross(a - c, q - c), n)
    inside = (s0 >= 0) & (s1 >= 0) & (s2 >= 0) & (nn > 0)
    plane = np.abs(h) * np.sqrt(nn)
    return np.where(inside, np.minimum(best, plane), best)
