#include "bench_embree.hpp"

#include <chrono>
#include <thread>

#include "peak_memory.hpp"
#include "rtcl/error.hpp"

#ifdef RTCL_HAVE_EMBREE
#include "bench/support/embree_baseline.hpp"
#endif

namespace rtcl::cli {

namespace {
using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
}  // namespace

#ifdef RTCL_HAVE_EMBREE

struct EmbreeBaseline::Impl {
  bench::EmbreeScene scene;
};

std::string embree_baseline_version(unsigned threads) { return bench::embree_version(threads); }

EmbreeBaseline::EmbreeBaseline(const Geometry& geometry, unsigned threads, bool robust, int builds)
    : geometry_(&geometry), threads_(threads), robust_(robust) {
  for (int b = 0; b < builds; ++b) {
    impl_.reset();
    std::this_thread::sleep_for(kBuildPause);
    PeakMemory peak;
    impl_.reset(new Impl{bench::EmbreeScene(geometry, bench::EmbreeQuality::standard, threads, robust)});
    build_peak_bytes_ = peak.peak_extra_bytes();
    build_ms_runs_.push_back(impl_->scene.build_ms());
  }
  if (!impl_) throw Error("Embree baseline: no build");
}

bool EmbreeBaseline::has_packets() const { return bench::embree_has_packet8(threads_); }

double EmbreeBaseline::build_once_ms() const {
  return bench::EmbreeScene(*geometry_, bench::EmbreeQuality::standard, threads_, robust_).build_ms();
}

std::vector<Hit> EmbreeBaseline::measure(Query query, bool packets, const std::vector<Ray>& rays, int repeat,
                                         BenchBaseline& out) const {
  const bench::EmbreeScene& embree = impl_->scene;
  const bench::EmbreeApi api = packets ? bench::EmbreeApi::packet8 : bench::EmbreeApi::single;
  out.api = bench::embree_api_name(api, query);
  out.packets = packets;
  out.threads = threads_;
  out.ray_count = rays.size();
  out.build_ms = spread_of(build_ms_runs_).median;
  out.build_ms_runs = build_ms_runs_;
  out.bytes = embree.bytes();
  out.build_peak_bytes = build_peak_bytes_;
  std::vector<Hit> hits(rays.size());
  if (rays.empty()) return hits;
  embree.trace(query, rays.data(), hits.data(), rays.size(), threads_, api);  // warm-up: page-in, threads
  for (int r = 0; r < repeat; ++r) {
    Clock::time_point start = Clock::now();
    out.trace_ms.push_back(trace_ms(query, packets, rays));
    embree.answers(hits.data());
    out.wall_ms.push_back(ms_between(start, Clock::now()));
  }
  return hits;
}

double EmbreeBaseline::trace_ms(Query query, bool packets, const std::vector<Ray>& rays) const {
  const bench::EmbreeScene& embree = impl_->scene;
  if (rays.empty()) return 0.0;
  embree.prepare(query, rays.data(), rays.size(), packets ? bench::EmbreeApi::packet8 : bench::EmbreeApi::single);
  Clock::time_point start = Clock::now();
  embree.trace_prepared(threads_);
  return ms_between(start, Clock::now());
}

#else

struct EmbreeBaseline::Impl {};

std::string embree_baseline_version(unsigned) { return ""; }

EmbreeBaseline::EmbreeBaseline(const Geometry& geometry, unsigned threads, bool robust, int)
    : geometry_(&geometry), threads_(threads), robust_(robust) {
  throw Error("rtcl was built without Embree: no Embree baseline");
}

bool EmbreeBaseline::has_packets() const { return false; }

double EmbreeBaseline::build_once_ms() const { return 0.0; }

std::vector<Hit> EmbreeBaseline::measure(Query, bool, const std::vector<Ray>&, int, BenchBaseline&) const {
  return {};
}

double EmbreeBaseline::trace_ms(Query, bool, const std::vector<Ray>&) const { return 0.0; }

#endif

EmbreeBaseline::~EmbreeBaseline() = default;

}  // namespace rtcl::cli
