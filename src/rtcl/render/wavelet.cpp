#include "rtcl/render/wavelet.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include "rtcl/error.hpp"
#include "rtcl/render/haar.hpp"

namespace rtcl {

void check_wavelet(const WaveletSettings& s) {
  if (s.block == 0 || s.block > 256)
    throw Error("wavelet block " + std::to_string(s.block) + ": must be 1 .. 256 pixels");
  if (!std::isfinite(s.budget) || s.budget <= 0.0f || s.budget > 1.0f)
    throw Error("wavelet budget " + std::to_string(s.budget) + ": must be in (0, 1], the share of pixels traced");
}

std::vector<double> haar_importance(const std::vector<float>& rgb, std::uint32_t gw, std::uint32_t gh) {
  std::uint32_t n = 1;
  while (n < std::max(gw, gh) + 1) n *= 2;  // room for the shift
  std::vector<double> importance(std::size_t(gw) * gh, 0.0);
  std::vector<double> c(std::size_t(n) * n);
  // Point (x, y) of the grid is at (x + sx, y + sy) of the shifted copy.
  for (std::uint32_t shift = 0; shift < 4; ++shift) {
    const std::uint32_t sx = shift & 1u, sy = shift >> 1;
    for (int ch = 0; ch < 3; ++ch) {
      for (std::uint32_t y = 0; y < n; ++y)
        for (std::uint32_t x = 0; x < n; ++x) {
          const std::uint32_t gx = std::min(x > sx ? x - sx : 0u, gw - 1), gy = std::min(y > sy ? y - sy : 0u, gh - 1);
          c[std::size_t(y) * n + x] = rgb[(std::size_t(gy) * gw + gx) * 3 + ch];
        }
      haar_2d(c, n);
      // Level s (s = n .. 2): the details of group (i, j) lie at (i + s/2, j),
      // (i, j + s/2), (i + s/2, j + s/2) and cover the points
      // [i, i + 1) * (n / (s/2)) in x (and so in y) of the shifted copy.
      for (std::uint32_t s = n; s >= 2; s /= 2) {
        const std::uint32_t h = s / 2, span = n / h;
        const double per_point = 1.0 / (double(span) * span);
        for (std::uint32_t j = 0; j < h; ++j)
          for (std::uint32_t i = 0; i < h; ++i) {
            const double dx = c[std::size_t(j) * n + i + h], dy = c[std::size_t(j + h) * n + i],
                         dd = c[std::size_t(j + h) * n + i + h];
            const double e = (dx * dx + dy * dy + dd * dd) * per_point;
            if (e == 0.0) continue;
            for (std::uint32_t y = std::max(j * span, sy); y < std::min((j + 1) * span, gh + sy); ++y)
              for (std::uint32_t x = std::max(i * span, sx); x < std::min((i + 1) * span, gw + sx); ++x)
                importance[std::size_t(y - sy) * gw + x - sx] += e;
          }
      }
    }
  }
  return importance;
}

namespace {

double pixels_of(const Block& b) { return double(b.x1 - b.x0 + 1) * (b.y1 - b.y0 + 1); }

// The squared Haar details of a block's four corners (display values), summed
// over the channels: the 2x2 transform of haar.hpp on (x0, y0), (x1, y0),
// (x0, y1), (x1, y1). 0 exactly when the corners agree.
double corner_detail_energy(const SparseImage& image, const Block& b) {
  double e = 0.0;
  for (int c = 0; c < 3; ++c) {
    auto v = [&](std::uint32_t x, std::uint32_t y) {
      return double(std::clamp(image.rgb[image.index(x, y) * 3 + c], 0.0f, 1.0f));
    };
    const double a = v(b.x0, b.y0), p = v(b.x1, b.y0), q = v(b.x0, b.y1), d = v(b.x1, b.y1);
    const double dx = (a - p + q - d) / 2, dy = (a + p - q - d) / 2, dd = (a - p - q + d) / 2;
    e += dx * dx + dy * dy + dd * dd;
  }
  return e;
}

}  // namespace

Image render_wavelet(const PixelTracer& tracer, std::uint32_t width, std::uint32_t height, const WaveletSettings& s,
                     SelectiveStats* stats) {
  check_wavelet(s);
  auto start = std::chrono::steady_clock::now();
  SparseImage image(width, height);
  const std::uint64_t pixels = std::uint64_t(width) * height;
  const auto budget = static_cast<std::uint64_t>(std::floor(double(s.budget) * double(pixels)));
  const std::vector<Block> blocks = block_grid(width, height, s.block);
  // The coarse grid: the blocks' corners, gw x gh points.
  std::uint32_t gw = 1, gh = 1;
  while (gw < blocks.size() && blocks[gw].y0 == blocks[0].y0) ++gw;
  gh = static_cast<std::uint32_t>(blocks.size() / gw);
  std::vector<std::uint32_t> corners;
  for (const Block& b : blocks) append_corners(image, b, corners);
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  if (corners.size() > budget)
    throw Error("wavelet budget " + std::to_string(s.budget) + ": the coarse pass (block " +
                std::to_string(s.block) + ") alone traces " + std::to_string(corners.size()) + " of " +
                std::to_string(pixels) + " pixels; raise the budget or the block");
  image.trace(tracer, corners);

  // Point (i, j) of the grid is the corner (x0 of column i, y0 of row j);
  // the last point of a row or column is its blocks' far corner.
  const std::uint32_t pw = gw + (blocks[gw - 1].x1 > blocks[gw - 1].x0 ? 1 : 0);
  const std::uint32_t ph = gh + (blocks.back().y1 > blocks.back().y0 ? 1 : 0);
  auto point_x = [&](std::uint32_t i) { return i < gw ? blocks[i].x0 : blocks[gw - 1].x1; };
  auto point_y = [&](std::uint32_t j) { return j < gh ? blocks[std::size_t(j) * gw].y0 : blocks.back().y1; };
  std::vector<float> coarse(std::size_t(pw) * ph * 3);
  for (std::uint32_t j = 0; j < ph; ++j)
    for (std::uint32_t i = 0; i < pw; ++i)
      for (int c = 0; c < 3; ++c)
        coarse[(std::size_t(j) * pw + i) * 3 + c] =
            std::clamp(image.rgb[image.index(point_x(i), point_y(j)) * 3 + c], 0.0f, 1.0f);
  const std::vector<double> importance = haar_importance(coarse, pw, ph);
  std::vector<double> score(blocks.size());
  for (std::uint32_t j = 0; j < gh; ++j)
    for (std::uint32_t i = 0; i < gw; ++i) {
      const std::uint32_t i1 = std::min(i + 1, pw - 1), j1 = std::min(j + 1, ph - 1);
      score[std::size_t(j) * gw + i] = importance[std::size_t(j) * pw + i] + importance[std::size_t(j) * pw + i1] +
                                       importance[std::size_t(j1) * pw + i] + importance[std::size_t(j1) * pw + i1];
    }
  struct Ranked {
    Block block;
    double priority;
  };
  std::vector<Ranked> active, kept;
  // A first block's priority: its corners' importance over the four shifts
  // (comparable with a cut block's corner_detail_energy), times its pixels.
  for (std::size_t k = 0; k < blocks.size(); ++k) active.push_back({blocks[k], score[k] / 4.0 * pixels_of(blocks[k])});
  std::uint64_t left = budget - image.traced_count;
  std::vector<Block> children;
  std::vector<std::uint32_t> queued, corners_of;
  std::vector<std::uint8_t> in_queue(image.traced.size(), 0);
  // Rounds: the blocks of every level in one ranking; each round cuts the
  // most important ones, spending at most half of what is left (at least
  // 256 pixels), and traces their new corners in one batch.
  for (bool progress = true; progress && left > 0 && !active.empty();) {
    std::stable_sort(active.begin(), active.end(),
                     [](const Ranked& a, const Ranked& b) { return a.priority > b.priority; });
    const std::uint64_t cap = std::min(left, std::max<std::uint64_t>(left / 2, 256));
    std::uint64_t spent = 0;
    std::size_t done = 0;
    queued.clear();
    kept.clear();
    for (; done < active.size(); ++done) {
      const Block& b = active[done].block;
      if (b.x1 - b.x0 <= 1 && b.y1 - b.y0 <= 1) continue;  // every pixel is a corner
      children.clear();
      split(b, children);
      corners_of.clear();
      for (const Block& c : children) append_corners(image, c, corners_of);
      const std::size_t before = queued.size();
      for (std::uint32_t p : corners_of)
        if (!image.traced[p] && !in_queue[p]) {
          in_queue[p] = 1;
          queued.push_back(p);
        }
      const std::uint64_t cost = queued.size() - before;
      if (spent + cost > cap) {  // not this round: undo
        for (std::size_t i = before; i < queued.size(); ++i) in_queue[queued[i]] = 0;
        queued.resize(before);
        break;
      }
      spent += cost;
      for (const Block& c : children) kept.push_back({c, -1.0});
    }
    progress = done > 0;
    kept.insert(kept.end(), active.begin() + std::ptrdiff_t(done), active.end());
    image.trace(tracer, queued);
    left -= spent;
    for (Ranked& r : kept)
      if (r.priority < 0.0) r.priority = corner_detail_energy(image, r.block) * pixels_of(r.block);
    std::swap(active, kept);
  }
  std::vector<Block> interpolated;
  for (const Ranked& r : active) interpolated.push_back(r.block);
  for (const Block& b : interpolated) interpolate_block(image, b);
  if (stats) {
    stats->traced_pixels = image.traced_count;
    stats->launches = image.launches;
    stats->render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return image.image();
}

Image render_wavelet(Renderer& renderer, const RenderSettings& settings, const WaveletSettings& s,
                     SelectiveStats* stats) {
  SelectiveStats local;
  SelectiveStats* out = stats ? stats : &local;
  *out = SelectiveStats{};
  return render_wavelet(renderer_tracer(renderer, settings, out), settings.width, settings.height, s, out);
}

}  // namespace rtcl
