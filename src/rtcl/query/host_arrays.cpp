// The public host-array views (rtcl/queries.hpp).
#include <cmath>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/queries.hpp"

namespace rtcl {

Rays::Rays(std::span<const float> origins, std::span<const float> directions, std::span<const float> tmin,
           std::span<const float> tmax)
    : origins_(origins), directions_(directions), tmin_(tmin), tmax_(tmax), count_(origins.size() / 3) {
  auto count = [](std::span<const float> a) { return std::to_string(a.size()); };
  if (origins.size() % 3 != 0)
    throw Error("rays: origins holds " + count(origins) + " floats, not 3 per ray");
  if (directions.size() != origins.size())
    throw Error("rays: directions holds " + count(directions) + " floats, origins " + count(origins) +
                " (3 per ray each)");
  if (!tmin.empty() && tmin.size() != count_)
    throw Error("rays: tmin holds " + count(tmin) + " values for " + std::to_string(count_) + " rays");
  if (!tmax.empty() && tmax.size() != count_)
    throw Error("rays: tmax holds " + count(tmax) + " values for " + std::to_string(count_) + " rays");
  if (count_ > 0 && (!origins.data() || !directions.data())) throw Error("rays: null origins or directions");
  if ((!tmin.empty() && !tmin.data()) || (!tmax.empty() && !tmax.data())) throw Error("rays: null tmin or tmax");
}

void Rays::pack(std::size_t first, std::span<Ray> out) const {
  if (!records_.empty()) {
    std::copy_n(records_.begin() + static_cast<std::ptrdiff_t>(first), out.size(), out.begin());
    return;
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t i = first + k;
    const float* o = origins_.data() + 3 * i;
    const float* d = directions_.data() + 3 * i;
    out[k] = Ray{o[0], o[1], o[2], d[0], d[1], d[2], tmin_.empty() ? 0.0f : tmin_[i],
                 tmax_.empty() ? INFINITY : tmax_[i]};
  }
}

Points::Points(std::span<const float> xyz) : xyz_(xyz), count_(xyz.size() / 3) {
  if (xyz.size() % 3 != 0) throw Error("points: holds " + std::to_string(xyz.size()) + " floats, not 3 per point");
  if (count_ > 0 && !xyz.data()) throw Error("points: null array");
}

}  // namespace rtcl
