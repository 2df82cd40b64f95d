#include "rtcl/render/haar.hpp"

#include <cmath>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

const double inv_sqrt2 = 1.0 / std::sqrt(2.0);

bool power_of_two(std::size_t n) { return n > 0 && (n & (n - 1)) == 0; }

// n: the side; values: the data's length; dims: 1 or 2.
void check_size(std::size_t n, std::size_t values, int dims) {
  if (!power_of_two(n) || values != (dims == 2 ? n * n : n))
    throw Error("Haar transform (" + std::to_string(dims) + "D): side " + std::to_string(n) + " with " +
                std::to_string(values) + " values: the side must be a power of two and the data " +
                (dims == 2 ? "side * side" : "side") + " values");
}

// One level on the s values at base, base + stride, ...: averages then details.
void forward_step(double* base, std::size_t stride, std::size_t s, std::vector<double>& tmp) {
  const std::size_t h = s / 2;
  for (std::size_t i = 0; i < h; ++i) {
    const double a = base[2 * i * stride], b = base[(2 * i + 1) * stride];
    tmp[i] = (a + b) * inv_sqrt2;
    tmp[h + i] = (a - b) * inv_sqrt2;
  }
  for (std::size_t i = 0; i < s; ++i) base[i * stride] = tmp[i];
}

void inverse_step(double* base, std::size_t stride, std::size_t s, std::vector<double>& tmp) {
  const std::size_t h = s / 2;
  for (std::size_t i = 0; i < h; ++i) {
    const double a = base[i * stride], d = base[(h + i) * stride];
    tmp[2 * i] = (a + d) * inv_sqrt2;
    tmp[2 * i + 1] = (a - d) * inv_sqrt2;
  }
  for (std::size_t i = 0; i < s; ++i) base[i * stride] = tmp[i];
}

}  // namespace

void haar_1d(std::vector<double>& x) {
  check_size(x.size(), x.size(), 1);
  std::vector<double> tmp(x.size());
  for (std::size_t s = x.size(); s >= 2; s /= 2) forward_step(x.data(), 1, s, tmp);
}

void inverse_haar_1d(std::vector<double>& x) {
  check_size(x.size(), x.size(), 1);
  std::vector<double> tmp(x.size());
  for (std::size_t s = 2; s <= x.size(); s *= 2) inverse_step(x.data(), 1, s, tmp);
}

void haar_2d(std::vector<double>& data, std::uint32_t n) {
  check_size(n, data.size(), 2);
  std::vector<double> tmp(n);
  for (std::size_t s = n; s >= 2; s /= 2) {
    for (std::size_t y = 0; y < s; ++y) forward_step(&data[y * n], 1, s, tmp);
    for (std::size_t x = 0; x < s; ++x) forward_step(&data[x], n, s, tmp);
  }
}

void inverse_haar_2d(std::vector<double>& data, std::uint32_t n) {
  check_size(n, data.size(), 2);
  std::vector<double> tmp(n);
  for (std::size_t s = 2; s <= n; s *= 2) {
    for (std::size_t x = 0; x < s; ++x) inverse_step(&data[x], n, s, tmp);
    for (std::size_t y = 0; y < s; ++y) inverse_step(&data[y * n], 1, s, tmp);
  }
}

}  // namespace rtcl
