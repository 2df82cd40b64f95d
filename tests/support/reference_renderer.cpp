#include "support/reference_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "rtcl/render/camera.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "rtcl/scene/motion.hpp"
#include "rtcl/scene/orthonormal_basis.hpp"

namespace rtcl::test {

namespace {

using glm::dvec3;

// The same rule as RTCL_SHADOW_SHORTEN in kernels/render/shade.cl: a
// semantic choice (a light on a surface lights it), not a precision fix.
constexpr double shadow_shorten = 1e-4;
// The reference's own spawn offset, relative to the magnitudes involved: far
// above double rounding, far below the device's float offset.
constexpr double spawn_offset = 1e-9;

double max3(const dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
double max_abs3(const dvec3& v) { return max3(glm::abs(v)); }

struct RefHit {
  double t = std::numeric_limits<double>::infinity();
  int prim = -1;
  double u = 0.0, v = 0.0;
};

class Tracer {
 public:
  // A moving scene's primitives are its keyframes at the camera's shutter
  // open and close (flattened to float, as the renderer's input), each
  // sample's at open + tau * (close - open) in double.
  Tracer(const SceneDescription& scene, const RenderSettings& settings) : scene_(scene), settings_(settings) {
    const bool moves = scene_moves(scene);
    FlatScene flat = flatten(moves ? scene_at(scene, scene.camera.shutter_open) : scene);
    FlatScene end = moves ? flatten(scene_at(scene, scene.camera.shutter_close)) : flat;
    material_ = flat.material;
    lights_ = expand_emissive_lights(moves ? scene_at(scene, scene.camera.shutter_open) : scene, flat);
    const Geometry& g = flat.geometry;
    const Geometry& ge = end.geometry;
    for (std::size_t t = 0; t < g.triangles.size(); ++t) {
      Tri tri;
      for (int k = 0; k < 3; ++k) {
        tri.v[k] = dvec3(g.vertices[g.triangles[t][k]]);
        tri.motion[k] = dvec3(ge.vertices[ge.triangles[t][k]]) - tri.v[k];
      }
      tri.skip = zero_area(g, t);  // no structure stores zero-area triangles
      triangles_.push_back(tri);
    }
    for (std::size_t i = 0; i < g.spheres.size(); ++i)
      spheres_.push_back({dvec3(g.spheres[i].center), double(g.spheres[i].radius),
                          dvec3(ge.spheres[i].center) - dvec3(g.spheres[i].center),
                          double(ge.spheres[i].radius) - double(g.spheres[i].radius)});
  }

  // The sample being traced: the sampler's points come from (pixel, sample);
  // tau is its time (a fraction of the shutter interval).
  struct SampleId {
    std::uint32_t pixel = 0, sample = 0;
    double tau = 0.0;
  };

  void sample_2d(const SampleId& id, std::uint32_t dimension, std::uint32_t index, std::uint32_t count, double& u,
                 double& v) const {
    float fu, fv;
    rtcl_sample_2d(static_cast<std::uint32_t>(settings_.sampler), settings_.seed, id.pixel, dimension, index, count,
                   &fu, &fv);
    u = fu;
    v = fv;
  }

  // A point of light l for the shading point p at (u, v) (the rules of
  // light_point in kernels/render/shade.cl), in double.
  static dvec3 light_point(const Light& l, const dvec3& p, double u, double v) {
    dvec3 c(l.position);
    if (l.shape == LightShape::point) return c;
    if (l.shape == LightShape::quad)
      return c - 0.5 * (dvec3(l.edge1) + dvec3(l.edge2)) + u * dvec3(l.edge1) + v * dvec3(l.edge2);
    if (l.shape == LightShape::triangle) {
      if (u + v > 1.0) {  // the kernel's fold, on the same float sample values
        u = 1.0 - u;
        v = 1.0 - v;
      }
      return c + u * dvec3(l.edge1) + v * dvec3(l.edge2);
    }
    float fx, fy;
    rtcl_concentric_disc(static_cast<float>(u), static_cast<float>(v), &fx, &fy);
    double x = fx, y = fy;
    dvec3 n = l.shape == LightShape::disc ? glm::normalize(dvec3(l.normal)) : glm::normalize(c - p);
    dvec3 t1, t2;
    orthonormal_basis(n, t1, t2);
    return c + double(l.radius) * (x * t1 + y * t2);
  }

  // Radiance along the unit direction d from o; `signature` mixes in every
  // decision the ray tree makes.
  dvec3 trace(const dvec3& o, const dvec3& d, const dvec3& w, std::uint32_t depth, const SampleId& id,
              std::uint64_t& signature) const {
    RefHit h = closest(o, d, std::numeric_limits<double>::infinity(), false, id.tau);
    mix(signature, static_cast<std::uint64_t>(h.prim + 1));
    if (h.prim < 0) return w * dvec3(scene_.background);

    // Surface point rebuilt from the primitive, geometric normal.
    dvec3 p, ng;
    double extent;
    if (static_cast<std::size_t>(h.prim) < triangles_.size()) {
      const Tri t = triangles_[h.prim].at(id.tau);
      dvec3 e1 = t.v[1] - t.v[0], e2 = t.v[2] - t.v[0];
      p = t.v[0] + h.u * e1 + h.v * e2;
      ng = glm::normalize(glm::cross(e1, e2));
      extent = std::max(max_abs3(e1), max_abs3(e2));
    } else {
      const Ball s = spheres_[h.prim - triangles_.size()].at(id.tau);
      ng = glm::normalize(o + h.t * d - s.center);
      p = s.center + s.radius * ng;
      extent = s.radius;
    }
    const Material& m = scene_.materials[material_[h.prim]];
    double offset = spawn_offset * (max_abs3(p) + extent);
    double cos_i = -glm::dot(d, ng);
    bool front = cos_i > 0.0;
    dvec3 n = front ? ng : -ng;
    cos_i = std::abs(cos_i);
    dvec3 above = p + offset * n;
    dvec3 radiance = w * (dvec3(m.emission) + dvec3(scene_.ambient) * dvec3(m.ambient));

    const auto light_count = static_cast<std::uint32_t>(lights_.size());
    for (std::uint32_t l = 0; l < light_count; ++l) {
      const Light& light = lights_[l];
      std::uint32_t points = light.area() ? settings_.light_samples : 1u;
      for (std::uint32_t j = 0; j < points; ++j) {
        double u = 0.0, v = 0.0;
        if (light.area())
          sample_2d(id, rtcl_dimension_light(depth, light_count, l), id.sample * points + j, settings_.spp * points, u,
                    v);
        dvec3 q = light_point(light, p, u, v);
        dvec3 ld = glm::normalize(q - p);
        double cos_l = glm::dot(n, ld);
        if (!(cos_l > 0.0)) continue;
        dvec3 f = dvec3(m.diffuse) * cos_l;
        if (max3(dvec3(m.specular)) > 0.0) {
          dvec3 mirror = 2.0 * cos_l * n - ld;
          double rv = std::max(glm::dot(mirror, -d), 0.0);
          f += dvec3(m.specular) * (m.shininess > 0.0f ? std::pow(rv, double(m.shininess)) : 1.0);
        }
        dvec3 c = w * dvec3(light.color) * double(light.intensity) * f / double(points);
        if (!(max3(c) > 0.0)) continue;
        bool occluded = closest(above, q - above, 1.0 - shadow_shorten, true, id.tau).prim >= 0;
        mix(signature, occluded ? 0x51u : 0x52u);
        if (!occluded) radiance += c;
      }
    }

    if (depth >= settings_.max_depth || (!m.reflective() && !m.transmissive())) return radiance;
    const double min_weight = settings_.min_weight;
    dvec3 wr = w * dvec3(m.kr);
    if (m.transmissive()) {
      double eta = front ? 1.0 / m.ior : double(m.ior);
      double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
      double F = 1.0;
      if (sin2_t < 1.0) {
        double cos_t = std::sqrt(1.0 - sin2_t);
        double rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        double rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        F = 0.5 * (rs * rs + rp * rp);
        dvec3 wt = w * dvec3(m.kt) * (1.0 - F);
        if (max3(wt) > 0.0 && max3(wt) >= min_weight) {
          dvec3 td = glm::normalize(eta * d + (eta * cos_i - cos_t) * n);
          radiance += trace(p - offset * n, td, wt, depth + 1, id, signature);
        }
      }
      wr += w * dvec3(m.kt) * F;
    }
    if (!(max3(wr) > 0.0 && max3(wr) >= min_weight)) return radiance;
    dvec3 rd = glm::normalize(d + 2.0 * cos_i * n);
    if (m.roughness > 0.0f) {  // a direction of the Phong lobe around the mirror direction
      double u, v;
      sample_2d(id, rtcl_dimension_glossy(depth, light_count), id.sample, settings_.spp, u, v);
      double exponent = 2.0 / (double(m.roughness) * m.roughness) - 2.0;
      double cos_a = std::pow(1.0 - u, 1.0 / (exponent + 1.0));
      double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
      double phi = 2.0 * std::numbers::pi * v;
      dvec3 t1, t2;
      orthonormal_basis(rd, t1, t2);
      rd = cos_a * rd + sin_a * (std::cos(phi) * t1 + std::sin(phi) * t2);
      mix(signature, glm::dot(rd, n) > 0.0 ? 0x61u : 0x62u);
      if (!(glm::dot(rd, n) > 0.0)) return radiance;
    }
    radiance += trace(above, rd, wr, depth + 1, id, signature);
    return radiance;
  }

 private:
  struct Tri {
    dvec3 v[3];
    dvec3 motion[3];  // close - open per vertex (zero when static)
    bool skip = false;
    Tri at(double tau) const {
      Tri t = *this;
      for (int k = 0; k < 3; ++k) t.v[k] = v[k] + tau * motion[k];
      return t;
    }
  };
  struct Ball {
    dvec3 center;
    double radius;
    dvec3 center_motion{0.0};
    double radius_motion = 0.0;
    Ball at(double tau) const { return {center + tau * center_motion, radius + tau * radius_motion}; }
  };

  static void mix(std::uint64_t& s, std::uint64_t value) {
    s ^= value + 0x9e3779b97f4a7c15ull + (s << 6) + (s >> 2);
  }

  // Nearest hit with 0 <= t <= tmax (t in units of |d|) at time tau; any:
  // the first found.
  RefHit closest(const dvec3& o, const dvec3& d, double tmax, bool any, double tau) const {
    RefHit best;
    best.t = tmax;
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
      const Tri tri = triangles_[i].at(tau);
      if (tri.skip) continue;
      // Möller-Trumbore in double.
      dvec3 e1 = tri.v[1] - tri.v[0], e2 = tri.v[2] - tri.v[0];
      dvec3 pv = glm::cross(d, e2);
      double det = glm::dot(e1, pv);
      if (det == 0.0) continue;
      dvec3 tv = o - tri.v[0];
      double u = glm::dot(tv, pv) / det;
      if (u < 0.0 || u > 1.0) continue;
      dvec3 qv = glm::cross(tv, e1);
      double v = glm::dot(d, qv) / det;
      if (v < 0.0 || u + v > 1.0) continue;
      double t = glm::dot(e2, qv) / det;
      if (t < 0.0 || t > best.t) continue;
      best = RefHit{t, static_cast<int>(i), u, v};
      if (any) return best;
    }
    double a = glm::dot(d, d);
    for (std::size_t i = 0; i < spheres_.size(); ++i) {
      const Ball s = spheres_[i].at(tau);
      dvec3 f = o - s.center;
      double b = -glm::dot(f, d);
      dvec3 l = f + (b / a) * d;
      double disc = a * (s.radius * s.radius - glm::dot(l, l));
      if (disc < 0.0) continue;
      double q = b + std::copysign(std::sqrt(disc), b);
      double c = glm::dot(f, f) - s.radius * s.radius;
      double t0 = c / q, t1 = q / a;
      for (double t : {std::min(t0, t1), std::max(t0, t1)}) {
        if (t < 0.0 || t > best.t) continue;
        best = RefHit{t, static_cast<int>(triangles_.size() + i), 0.0, 0.0};
        if (any) return best;
        break;
      }
    }
    if (best.prim < 0) best.t = std::numeric_limits<double>::infinity();
    return best;
  }

  const SceneDescription& scene_;
  RenderSettings settings_;
  std::vector<std::uint32_t> material_;
  std::vector<Light> lights_;  // emissive lights expanded into triangles
  std::vector<Tri> triangles_;
  std::vector<Ball> spheres_;
};

}  // namespace

ReferenceImage reference_render(const SceneDescription& scene, const RenderSettings& settings, double ambiguity_px) {
  Tracer tracer(scene, settings);
  CameraFrame frame = camera_frame(scene.camera, settings.width, settings.height);
  ReferenceImage out;
  out.image.width = settings.width;
  out.image.height = settings.height;
  std::size_t pixels = std::size_t(settings.width) * settings.height;
  out.image.rgb.assign(pixels * 3, 0.0f);
  out.ambiguous.assign(pixels, 0);
  const double offsets[5][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  // The thin lens (kernels/render/generate.cl).
  const Camera& camera = scene.camera;
  const double lens_radius = camera.aperture;
  const double focus = camera.focus_distance > 0.0f
                           ? double(camera.focus_distance)
                           : glm::length(dvec3(camera.look_at) - dvec3(camera.position));
  const dvec3 right = glm::normalize(frame.du), up = -glm::normalize(frame.dv);
  for (std::uint32_t y = 0; y < settings.height; ++y)
    for (std::uint32_t x = 0; x < settings.width; ++x) {
      std::uint32_t pixel = y * settings.width + x;
      dvec3 sum(0.0);
      for (std::uint32_t sample = 0; sample < settings.spp; ++sample) {
        const auto sampler = static_cast<std::uint32_t>(settings.sampler);
        float su, sv, jx, jy;
        rtcl_sample_2d(sampler, settings.seed, pixel, RTCL_DIM_PIXEL, sample, settings.spp, &su, &sv);
        rtcl_filter_offset(static_cast<std::uint32_t>(settings.filter), su, sv, &jx, &jy);
        dvec3 lens(0.0);
        if (lens_radius > 0.0) {
          float lu, lv, a, b;
          rtcl_sample_2d(sampler, settings.seed, pixel, RTCL_DIM_LENS, sample, settings.spp, &lu, &lv);
          rtcl_concentric_disc(lu, lv, &a, &b);
          lens = lens_radius * (double(a) * right + double(b) * up);
        }
        std::uint64_t signature[5] = {};
        for (int k = 0; k < 5; ++k) {
          double fx = x + 0.5 + double(jx) + offsets[k][0] * ambiguity_px;
          double fy = y + 0.5 + double(jy) + offsets[k][1] * ambiguity_px;
          dvec3 pinhole = frame.corner + fx * frame.du + fy * frame.dv;  // unit length along the view
          dvec3 d = glm::normalize(lens_radius > 0.0 ? focus * pinhole - lens : pinhole);
          double tau = rtcl_sample_time(sampler, settings.seed, pixel, sample, settings.spp);
          dvec3 radiance = tracer.trace(frame.origin + lens, d, dvec3(1.0), 0, {pixel, sample, tau}, signature[k]);
          if (k == 0) sum += radiance;
          if (signature[k] != signature[0]) out.ambiguous[pixel] = 1;
        }
      }
      for (int c = 0; c < 3; ++c) out.image.rgb[pixel * 3 + c] = static_cast<float>(sum[c] / settings.spp);
    }
  return out;
}

ImageDifference compare_images(const Image& a, const Image& b, const std::vector<std::uint8_t>& mask,
                               double over) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size())
    throw std::invalid_argument("compare_images: sizes differ");
  ImageDifference d;
  double sq = 0.0;
  std::size_t pixels = std::size_t(a.width) * a.height;
  for (std::size_t p = 0; p < pixels; ++p) {
    bool masked = !mask.empty() && mask[p];
    d.masked_pixels += masked;
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
      double e = std::abs(double(a.rgb[p * 3 + c]) - double(b.rgb[p * 3 + c]));
      if (std::isnan(e)) e = std::numeric_limits<double>::infinity();
      sq += e * e;
      worst = std::max(worst, e);
    }
    d.max_error = std::max(d.max_error, worst);
    if (!masked) d.max_error_unmasked = std::max(d.max_error_unmasked, worst);
    d.pixels_over += worst > over;
    d.pixels_over_unmasked += worst > over && !masked;
  }
  d.rmse = std::sqrt(sq / (3.0 * pixels));
  return d;
}

std::vector<std::uint8_t> edge_pixels(const Image& image, double step, int radius) {
  std::vector<std::uint8_t> edge(std::size_t(image.width) * image.height, 0);
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x)
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
          long nx = long(x) + dx, ny = long(y) + dy;
          if (nx < 0 || ny < 0 || nx >= long(image.width) || ny >= long(image.height)) continue;
          for (int c = 0; c < 3; ++c)
            if (std::abs(image.at(x, y, c) - image.at(std::uint32_t(nx), std::uint32_t(ny), c)) > step)
              edge[std::size_t(y) * image.width + x] = 1;
        }
  return edge;
}

}  // namespace rtcl::test
