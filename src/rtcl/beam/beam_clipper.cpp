#include "rtcl/beam/beam_clipper.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <string>

#include "rtcl/error.hpp"

namespace rtcl::beam {

namespace {

std::vector<BeamPolygon> pack(const std::vector<ScreenPolygon>& polygons) {
  std::vector<BeamPolygon> out(polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    const ScreenPolygon& p = polygons[i];
    if (p.v.size() < 3 || p.v.size() > RTCL_BEAM_POLYGON_VERTS)
      throw Error("beam clipping: screen polygon of triangle " + std::to_string(p.prim) + " has " +
                  std::to_string(p.v.size()) + " vertices (3 .. " + std::to_string(RTCL_BEAM_POLYGON_VERTS) + ")");
    BeamPolygon& b = out[i];
    b = BeamPolygon{};
    b.count = static_cast<rtcl_u32>(p.v.size());
    for (std::size_t k = 0; k < p.v.size(); ++k) {
      b.x[k] = static_cast<float>(p.v[k].x);
      b.y[k] = static_cast<float>(p.v[k].y);
    }
    for (int k = 0; k < 3; ++k) b.inv_depth[k] = static_cast<float>(p.inv_depth[k]);
  }
  return out;
}

}  // namespace

namespace {

// One launch over all beams of `tb` (retried once with a buffer of the size
// counted): the fragments in the device's order, and per beam 1 where it
// went over a limit (its fragments are then incomplete).
std::vector<BeamFragment> clip_once(const Device& device, const std::vector<BeamPolygon>& packed, const BeamSet& tb,
                                    DepthOrder order, std::vector<cl_uint>& over_limit, DeviceClipStats& st) {
  std::vector<std::uint32_t> candidates = tb.candidates;
  if (candidates.empty()) candidates.push_back(0);
  cl::Buffer polys = device.upload(packed.data(), packed.size() * sizeof(BeamPolygon), "beam polygons");
  cl::Buffer tiles = device.upload(tb.beams.data(), tb.beams.size() * sizeof(Beam), "beams");
  cl::Buffer cands = device.upload(candidates.data(), candidates.size() * sizeof(std::uint32_t), "beam candidates");
  cl::Program program = device.program("render/beam_clip.cl", {});
  cl::Kernel kernel(program, "clip_beams");
  // First guess: a few fragments per candidate; the kernel counts what it needed.
  std::size_t capacity = std::max<std::size_t>(1024, 2 * tb.candidates.size());
  std::vector<BeamFragment> out;
  for (int attempt = 0; attempt < 2; ++attempt) {
    device.check_fits(capacity * sizeof(BeamFragment), "beam fragment buffer");
    cl::Buffer frags = device.allocate(capacity * sizeof(BeamFragment), "beam fragments");
    std::array<cl_uint, RTCL_BEAM_STATUS_WORDS> status{};
    status[RTCL_BEAM_STATUS_FIRST_TILE] = 0xffffffffu;
    cl::Buffer status_buf = device.upload(status.data(), sizeof(status), "beam status");
    over_limit.assign(tb.beams.size(), 0);
    cl::Buffer over_buf = device.upload(over_limit.data(), over_limit.size() * sizeof(cl_uint), "beams over a limit");
    cl_uint a = 0;
    kernel.setArg(a++, polys);
    kernel.setArg(a++, tiles);
    kernel.setArg(a++, cands);
    kernel.setArg(a++, static_cast<cl_uint>(tb.beams.size()));
    kernel.setArg(a++, static_cast<cl_uint>(order == DepthOrder::exact));
    kernel.setArg(a++, device_min_area_fraction);
    kernel.setArg(a++, frags);
    kernel.setArg(a++, static_cast<cl_uint>(capacity));
    kernel.setArg(a++, status_buf);
    kernel.setArg(a++, over_buf);
    cl::Event done;
    // A small work-group: each work-item holds four regions of pieces
    // (about 17 KB) in private memory, which PoCL replicates per work-item
    // of a group on one thread's stack.
    const std::size_t group = 4, global = (tb.beams.size() + group - 1) / group * group;
    check_cl(device.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global), cl::NDRange(group),
                                                 nullptr, &done),
             "clEnqueueNDRangeKernel(clip_beams)");
    check_cl(device.queue().enqueueReadBuffer(status_buf, CL_TRUE, 0, sizeof(status), status.data(), nullptr, nullptr),
             "clEnqueueReadBuffer(beam status)");
    ++st.launches;
    if (device.profiling())
      st.clip_ms += (done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                     done.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-6;
    if (status[RTCL_BEAM_STATUS_PIECE_OVERFLOW] || status[RTCL_BEAM_STATUS_VERT_OVERFLOW])
      check_cl(device.queue().enqueueReadBuffer(over_buf, CL_TRUE, 0, over_limit.size() * sizeof(cl_uint),
                                                over_limit.data(), nullptr, nullptr),
               "clEnqueueReadBuffer(beams over a limit)");
    std::size_t wanted = status[RTCL_BEAM_STATUS_FRAGMENTS];
    if (wanted > capacity) {
      if (attempt == 1)
        throw Error("beam clipping: " + std::to_string(wanted) + " fragments do not fit the buffer of " +
                    std::to_string(capacity));
      capacity = wanted;
      continue;
    }
    out.resize(wanted);
    if (wanted)
      check_cl(device.queue().enqueueReadBuffer(frags, CL_TRUE, 0, wanted * sizeof(BeamFragment), out.data(), nullptr,
                                                nullptr),
               "clEnqueueReadBuffer(beam fragments)");
    break;
  }
  return out;
}

void sort_fragments(std::vector<BeamFragment>& out) {
  std::sort(out.begin(), out.end(), [](const BeamFragment& a, const BeamFragment& b) {
    return a.beam != b.beam ? a.beam < b.beam : a.seq < b.seq;
  });
}

std::vector<BeamFragment> clip_split(const Device& device, const std::vector<ScreenPolygon>& polygons,
                                     const std::vector<BeamPolygon>& packed, const BeamSet& tb, DepthOrder order,
                                     DeviceClipStats& st) {
  std::vector<cl_uint> over;
  std::vector<BeamFragment> out = clip_once(device, packed, tb, order, over, st);
  if (std::find(over.begin(), over.end(), 1u) == over.end()) {
    sort_fragments(out);
    return out;
  }
  // Each beam over a limit is cut into the four quarters of its bounding
  // box, which are clipped again (and cut again while they go over).
  out.erase(std::remove_if(out.begin(), out.end(), [&](const BeamFragment& f) { return over[f.beam] != 0; }),
            out.end());
  BeamSet quarters;
  std::vector<std::uint32_t> parent;
  for (std::uint32_t b = 0; b < tb.beams.size(); ++b) {
    if (!over[b]) continue;
    const Beam& beam = tb.beams[b];
    Convex section = cross_section(beam);
    glm::dvec2 lo = section.v[0], hi = section.v[0];
    for (const glm::dvec2& p : section.v) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    if (std::max(hi.x - lo.x, hi.y - lo.y) < min_split_px)
      throw Error("beam clipping: the beam at pixel (" + std::to_string(int(beam.x0)) + ", " +
                  std::to_string(int(beam.y0)) + "), cut to below " + std::to_string(min_split_px) +
                  " px, still needs more than " + std::to_string(RTCL_BEAM_MAX_PIECES) +
                  " convex pieces or a piece of more than " + std::to_string(RTCL_BEAM_PIECE_VERTS) +
                  " vertices (RTCL_BEAM_MAX_PIECES / RTCL_BEAM_PIECE_VERTS in kernels/shared/beam_layouts.h)");
    const glm::dvec2 mid = 0.5 * (lo + hi);
    const std::span<const std::uint32_t> cands(tb.candidates.data() + beam.first, beam.count);
    for (int q = 0; q < 4; ++q) {
      Convex part = intersect(section, rectangle(q & 1 ? mid.x : lo.x, q & 2 ? mid.y : lo.y, q & 1 ? hi.x : mid.x,
                                                 q & 2 ? hi.y : mid.y));
      if (part.v.size() < 3 || !(signed_area(part.v) > 0.0)) continue;
      add_beam(quarters, part, polygons, cands);
      parent.push_back(b);
    }
  }
  st.split_beams += quarters.beams.size();
  std::vector<BeamFragment> more = clip_split(device, polygons, packed, quarters, order, st);
  // The quarters' fragments become the parent's, in quarter order.
  std::vector<std::uint32_t> next_seq(tb.beams.size(), 0);
  for (BeamFragment f : more) {
    f.beam = parent[f.beam];
    f.seq = next_seq[f.beam]++;
    out.push_back(f);
  }
  sort_fragments(out);
  return out;
}

}  // namespace

std::vector<BeamFragment> clip_beams_device(const Device& device, const std::vector<ScreenPolygon>& polygons,
                                            const BeamSet& tb, DepthOrder order, DeviceClipStats* stats) {
  DeviceClipStats st;
  if (tb.beams.empty()) return {};
  std::vector<BeamPolygon> packed = pack(polygons);
  if (packed.empty()) packed.push_back(BeamPolygon{});  // no zero-sized buffers
  std::vector<BeamFragment> out = clip_split(device, polygons, packed, tb, order, st);
  st.fragments = out.size();
  if (stats) *stats = st;
  return out;
}

}  // namespace rtcl::beam
