// RaycastingScene.create_rays_pinhole: the camera rays of Open3D's function
// of the same name, both signatures, as an (height_px, width_px, 6) float32
// array in pixel order (row 0 first), directions not normalised: pixel
// (x, y) looks through image point (x + 0.5, y + 0.5, 1) of the camera.
#include <cmath>
#include <glm/glm.hpp>
#include <string>

#include "array_io.hpp"
#include "raycasting_scene.hpp"

namespace rtcl::python {

namespace {

constexpr const char* kCall = "create_rays_pinhole";

// A finite float array of `shape`, as doubles in C order.
std::vector<double> read_matrix(py::handle object, const std::vector<py::ssize_t>& shape, const char* param) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(std::string(kCall) + ": " + param + " must be a numeric array of shape " + shape_text(shape));
  }
  std::vector<py::ssize_t> got(a.shape(), a.shape() + a.ndim());
  if (got != shape)
    throw py::value_error(std::string(kCall) + ": " + param + " has shape " + shape_text(got) + "; expected " +
                          shape_text(shape));
  std::vector<double> v(a.data(), a.data() + a.size());
  for (double x : v)
    if (!std::isfinite(x)) throw py::value_error(std::string(kCall) + ": " + param + " has a NaN or infinite value");
  return v;
}

glm::dvec3 read_vector(py::handle object, const char* param) {
  std::vector<double> v = read_matrix(object, {3}, param);
  return {v[0], v[1], v[2]};
}

void check_size(long long size, const char* param) {
  if (size < 0 || size > (1 << 20))
    throw py::value_error(std::string(kCall) + ": " + param + " is " + std::to_string(size) + "; must be in [0, 2^20]");
}

// Rays from `eye` through pixel (x, y): direction right * (x + 0.5) +
// down * (y + 0.5) + corner (the columns of R^T K^-1).
py::array_t<float> pinhole_rays(const glm::dvec3& eye, const glm::dvec3& right, const glm::dvec3& down,
                                const glm::dvec3& corner, long long width, long long height) {
  auto rays = output_array<float>({static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width)}, {6});
  float* out = rays.mutable_data();
  py::gil_scoped_release release;
  for_parts(static_cast<std::size_t>(width * height), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const double x = static_cast<double>(i % static_cast<std::size_t>(width)) + 0.5;
      const double y = static_cast<double>(i / static_cast<std::size_t>(width)) + 0.5;
      const glm::dvec3 d = x * right + y * down + corner;
      float* r = out + 6 * i;
      r[0] = static_cast<float>(eye.x);
      r[1] = static_cast<float>(eye.y);
      r[2] = static_cast<float>(eye.z);
      r[3] = static_cast<float>(d.x);
      r[4] = static_cast<float>(d.y);
      r[5] = static_cast<float>(d.z);
    }
  });
  return rays;
}

py::array_t<float> from_matrices(py::handle intrinsic_matrix, py::handle extrinsic_matrix, long long width_px,
                                 long long height_px) {
  const std::vector<double> k = read_matrix(intrinsic_matrix, {3, 3}, "intrinsic_matrix");
  const std::vector<double> e = read_matrix(extrinsic_matrix, {4, 4}, "extrinsic_matrix");
  check_size(width_px, "width_px");
  check_size(height_px, "height_px");
  // The image point (x, y, 1) maps to camera vector K^-1 (x, y, 1).
  const glm::dmat3 kmat(k[0], k[3], k[6], k[1], k[4], k[7], k[2], k[5], k[8]);  // glm: columns
  if (!(std::abs(glm::determinant(kmat)) > 0.0))
    throw py::value_error(std::string(kCall) + ": intrinsic_matrix is singular");
  const glm::dmat3 kinv = glm::inverse(kmat);
  const glm::dvec3 kx = kinv[0], ky = kinv[1], k1 = kinv[2];
  // Extrinsic [R | t], world to camera: the camera centre is -R^T t and a
  // camera vector v is R^T v in the world.
  const glm::dmat3 rt(e[0], e[1], e[2], e[4], e[5], e[6], e[8], e[9], e[10]);  // columns of R^T: rows of R
  const glm::dvec3 t(e[3], e[7], e[11]);
  const glm::dvec3 eye = -(rt * t);
  return pinhole_rays(eye, rt * kx, rt * ky, rt * k1, width_px, height_px);
}

py::array_t<float> from_look_at(double fov_deg, py::handle center, py::handle eye_in, py::handle up_in,
                                long long width_px, long long height_px) {
  if (!(fov_deg > 0.0 && fov_deg < 180.0))
    throw py::value_error(std::string(kCall) + ": fov_deg is " + std::to_string(fov_deg) +
                          "; must be in (0, 180) (the horizontal field of view)");
  const glm::dvec3 target = read_vector(center, "center"), eye = read_vector(eye_in, "eye"),
                   up = read_vector(up_in, "up");
  check_size(width_px, "width_px");
  check_size(height_px, "height_px");
  const glm::dvec3 view = target - eye;
  if (glm::length(view) == 0.0) throw py::value_error(std::string(kCall) + ": center equals eye");
  if (glm::length(up) == 0.0) throw py::value_error(std::string(kCall) + ": up is the zero vector");
  // Open3D's camera frame: forward z towards the centre, x = up x z, y = z x x.
  const glm::dvec3 z = glm::normalize(view);
  const glm::dvec3 x_raw = glm::cross(glm::normalize(up), z);
  if (glm::length(x_raw) < 1e-12) throw py::value_error(std::string(kCall) + ": up is parallel to center - eye");
  const glm::dvec3 x = glm::normalize(x_raw), y = glm::cross(z, x);
  const double f = 0.5 * static_cast<double>(width_px) / std::tan(0.5 * glm::radians(fov_deg));
  const double cx = 0.5 * static_cast<double>(width_px), cy = 0.5 * static_cast<double>(height_px);
  return pinhole_rays(eye, x / f, y / f, z - (cx / f) * x - (cy / f) * y, width_px, height_px);
}

}  // namespace

void bind_pinhole(py::class_<MeshScene>& cls) {
  cls.def_static("create_rays_pinhole", &from_matrices, py::arg("intrinsic_matrix"), py::arg("extrinsic_matrix"),
                 py::arg("width_px"), py::arg("height_px"),
                 R"doc(Camera rays (height_px, width_px, 6) float32 of a pinhole camera:
intrinsic_matrix (3, 3), extrinsic_matrix (4, 4) world to
camera. Pixel (x, y) looks through (x + 0.5, y + 0.5, 1); the direction's
camera z is 1, so t_hit is the depth along the optical axis. As Open3D's.)doc");
  cls.def_static("create_rays_pinhole", &from_look_at, py::arg("fov_deg"), py::arg("center"), py::arg("eye"),
                 py::arg("up"), py::arg("width_px"), py::arg("height_px"),
                 R"doc(Camera rays (height_px, width_px, 6) float32 from eye towards center with a
horizontal field of view of fov_deg degrees. The camera frame is Open3D's
(x = up x forward, y = forward x x): row 0 of the image lies on the side of
-up and column 0 on the side of -(up x forward), the same rays as
Open3D's create_rays_pinhole.)doc");
}

}  // namespace rtcl::python
