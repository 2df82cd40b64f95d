#include "support/closed_meshes.hpp"

#include <cmath>
#include <map>
#include <random>
#include <tuple>

namespace rtcl::test {

namespace {

using Edge = std::pair<std::uint32_t, std::uint32_t>;

Edge undirected(std::uint32_t a, std::uint32_t b) { return a < b ? Edge{a, b} : Edge{b, a}; }

// Adds triangle (a, b, c), wound counter-clockwise seen from outside, where
// "outside" is the side away from the origin (all meshes here contain it).
void add_outward(Geometry& g, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  glm::dvec3 pa(g.vertices[a]), pb(g.vertices[b]), pc(g.vertices[c]);
  glm::dvec3 n = glm::cross(pb - pa, pc - pa);
  if (glm::dot(n, pa + pb + pc) < 0.0) std::swap(b, c);
  g.triangles.push_back({a, b, c});
}

// Unit-sphere icosphere in double precision, before any scaling.
void unit_icosphere(int levels, std::vector<glm::dvec3>& points, std::vector<glm::uvec3>& faces) {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  points = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
            {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (auto& p : points) p = glm::normalize(p);
  faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
           {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
           {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<Edge, std::uint32_t> midpoint;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      auto [it, added] = midpoint.try_emplace(undirected(a, b), static_cast<std::uint32_t>(points.size()));
      if (added) points.push_back(glm::normalize(points[a] + points[b]));
      return it->second;
    };
    std::vector<glm::uvec3> next;
    for (const auto& f : faces) {
      std::uint32_t ab = mid(f.x, f.y), bc = mid(f.y, f.z), ca = mid(f.z, f.x);
      next.insert(next.end(), {{f.x, ab, ca}, {f.y, bc, ab}, {f.z, ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(next);
  }
}

Geometry from_points(const std::vector<glm::dvec3>& points, const std::vector<glm::uvec3>& faces,
                     const std::vector<double>& radii, const char* name) {
  Geometry g;
  g.source = name;
  for (std::size_t i = 0; i < points.size(); ++i) g.vertices.push_back(glm::vec3(points[i] * radii[i]));
  for (const auto& f : faces) add_outward(g, f.x, f.y, f.z);
  return g;
}

}  // namespace

Geometry icosphere(int levels, float radius) {
  std::vector<glm::dvec3> points;
  std::vector<glm::uvec3> faces;
  unit_icosphere(levels, points, faces);
  return from_points(points, faces, std::vector<double>(points.size(), radius), "icosphere");
}

Geometry bumpy_sphere(int levels, float radius, float amplitude, std::uint32_t seed) {
  std::vector<glm::dvec3> points;
  std::vector<glm::uvec3> faces;
  unit_icosphere(levels, points, faces);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  std::vector<double> radii;
  for (std::size_t i = 0; i < points.size(); ++i) radii.push_back(radius * (1.0 + amplitude * noise(rng)));
  return from_points(points, faces, radii, "bumpy sphere");
}

Geometry uv_sphere(int stacks, int slices, float radius) {
  const double pi = std::acos(-1.0);
  Geometry g;
  g.source = "uv sphere";
  g.vertices.push_back({0.0f, radius, 0.0f});
  for (int i = 1; i < stacks; ++i) {
    double polar = pi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      double azimuth = 2.0 * pi * j / slices;
      g.vertices.push_back(glm::vec3(double(radius) * glm::dvec3(std::sin(polar) * std::cos(azimuth), std::cos(polar),
                                                         std::sin(polar) * std::sin(azimuth))));
    }
  }
  auto south = static_cast<std::uint32_t>(g.vertices.size());
  g.vertices.push_back({0.0f, -radius, 0.0f});
  auto ring = [&](int i, int j) { return static_cast<std::uint32_t>(1 + (i - 1) * slices + (j % slices)); };
  for (int j = 0; j < slices; ++j) {
    add_outward(g, 0, ring(1, j), ring(1, j + 1));
    add_outward(g, south, ring(stacks - 1, j), ring(stacks - 1, j + 1));
    for (int i = 1; i + 1 < stacks; ++i) {
      add_outward(g, ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
      add_outward(g, ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
    }
  }
  return g;
}

Geometry cube_grid(int n, float half) {
  Geometry g;
  g.source = "cube grid";
  std::map<std::tuple<int, int, int>, std::uint32_t> index;
  auto vertex = [&](glm::ivec3 c) {
    auto [it, added] = index.try_emplace({c.x, c.y, c.z}, static_cast<std::uint32_t>(g.vertices.size()));
    if (added) g.vertices.push_back(glm::vec3(glm::dvec3(c) * (2.0 * half / n) - glm::dvec3(half)));
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int side : {0, n}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          glm::ivec3 c[4];
          for (int k = 0; k < 4; ++k) {
            c[k][axis] = side;
            c[k][a1] = i + (k == 1 || k == 2);
            c[k][a2] = j + (k >= 2);
          }
          std::uint32_t q[4] = {vertex(c[0]), vertex(c[1]), vertex(c[2]), vertex(c[3])};
          if ((i + j) % 2 == 0) {
            add_outward(g, q[0], q[1], q[2]);
            add_outward(g, q[0], q[2], q[3]);
          } else {
            add_outward(g, q[0], q[1], q[3]);
            add_outward(g, q[1], q[2], q[3]);
          }
        }
      }
    }
  }
  return g;
}

Geometry staircase(int steps, int depth) {
  Geometry g;
  g.source = "staircase";
  auto occupied = [&](glm::ivec3 c) {
    return c.x >= 0 && c.x < steps && c.z >= 0 && c.z < depth && c.y >= 0 && c.y < steps - c.x;
  };
  std::map<std::tuple<int, int, int>, std::uint32_t> index;
  auto vertex = [&](glm::ivec3 c) {
    auto [it, added] = index.try_emplace({c.x, c.y, c.z}, static_cast<std::uint32_t>(g.vertices.size()));
    if (added) g.vertices.push_back(glm::vec3(c));
    return it->second;
  };
  for (int x = 0; x < steps; ++x)
    for (int y = 0; y < steps; ++y)
      for (int z = 0; z < depth; ++z) {
        glm::ivec3 cell(x, y, z);
        if (!occupied(cell)) continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side : {0, 1}) {
            glm::ivec3 out_dir(0);
            out_dir[axis] = side ? 1 : -1;
            if (occupied(cell + out_dir)) continue;
            // the face's corners, in order around it
            int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            glm::ivec3 c[4];
            for (int k = 0; k < 4; ++k) {
              c[k] = cell;
              c[k][axis] += side;
              c[k][a1] += (k == 1 || k == 2);
              c[k][a2] += (k >= 2);
            }
            std::uint32_t q[4] = {vertex(c[0]), vertex(c[1]), vertex(c[2]), vertex(c[3])};
            std::uint32_t tris[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
            if ((x + y + z) % 2) tris[0][2] = q[3], tris[1][0] = q[1];  // the other diagonal
            for (auto& t : tris) {
              glm::vec3 n = glm::cross(g.vertices[t[1]] - g.vertices[t[0]], g.vertices[t[2]] - g.vertices[t[0]]);
              if (glm::dot(n, glm::vec3(out_dir)) < 0.0f) std::swap(t[1], t[2]);
              g.triangles.push_back({t[0], t[1], t[2]});
            }
          }
      }
  return g;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> unique_edges(const Geometry& mesh) {
  std::map<Edge, int> seen;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) seen[undirected(t[k], t[(k + 1) % 3])];
  std::vector<Edge> edges;
  for (const auto& entry : seen) edges.push_back(entry.first);
  return edges;
}

std::vector<std::vector<std::uint32_t>> vertex_triangles(const Geometry& mesh) {
  std::vector<std::vector<std::uint32_t>> out(mesh.vertices.size());
  for (std::uint32_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) out[mesh.triangles[i][k]].push_back(i);
  return out;
}

std::size_t open_edges(const Geometry& mesh) {
  std::map<Edge, int> directed;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  std::size_t open = 0;
  for (const auto& [edge, count] : directed)
    if (count != 1 || directed.count({edge.second, edge.first}) == 0 ||
        directed.at({edge.second, edge.first}) != 1)
      ++open;
  return open;
}

}  // namespace rtcl::test
