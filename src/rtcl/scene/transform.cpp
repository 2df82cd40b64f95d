// rtcl::Transform (rtcl/scene.hpp): constructors in double, rounded to
// float once.
#include <cmath>

#include "rtcl/error.hpp"
#include "rtcl/scene.hpp"

namespace rtcl {

namespace {

using Rows = std::array<std::array<double, 4>, 3>;

Transform rounded(const Rows& d) {
  Transform t;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) t.m[row][col] = static_cast<float>(d[row][col]);
  return t;
}

}  // namespace

Transform Transform::translate(float x, float y, float z) {
  Transform t;
  t.m[0][3] = x;
  t.m[1][3] = y;
  t.m[2][3] = z;
  return t;
}

Transform Transform::scale(float x, float y, float z) {
  Transform t;
  t.m[0][0] = x;
  t.m[1][1] = y;
  t.m[2][2] = z;
  return t;
}

Transform Transform::rotate(float degrees, float x, float y, float z) {
  const double length = std::sqrt(double{x} * x + double{y} * y + double{z} * z);
  if (!(length > 0.0) || !std::isfinite(length))
    throw Error("Transform::rotate: the axis (" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                std::to_string(z) + ") must be finite and not zero");
  const double ux = x / length, uy = y / length, uz = z / length;
  const double angle = double{degrees} * (M_PI / 180.0);
  const double c = std::cos(angle), s = std::sin(angle), k = 1.0 - c;
  // Rodrigues' rotation formula.
  Rows r{{{c + ux * ux * k, ux * uy * k - uz * s, ux * uz * k + uy * s, 0.0},
          {uy * ux * k + uz * s, c + uy * uy * k, uy * uz * k - ux * s, 0.0},
          {uz * ux * k - uy * s, uz * uy * k + ux * s, c + uz * uz * k, 0.0}}};
  return rounded(r);
}

Transform Transform::from_rows(std::span<const float, 12> rows) {
  Transform t;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) t.m[row][col] = rows[static_cast<std::size_t>(4 * row + col)];
  return t;
}

Transform Transform::operator*(const Transform& b) const {
  Rows out{};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) {
      double v = col == 3 ? double{m[row][3]} : 0.0;
      for (int k = 0; k < 3; ++k) v += double{m[row][k]} * double{b.m[k][col]};
      out[row][col] = v;
    }
  return rounded(out);
}

}  // namespace rtcl
