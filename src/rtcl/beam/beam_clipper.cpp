#include "rtcl/beam/beam_clipper.hpp"

#include <algorithm>
#include <array>
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

std::vector<BeamFragment> clip_beams_device(const Device& device, const std::vector<ScreenPolygon>& polygons,
                                            const BeamSet& tb, DepthOrder order, DeviceClipStats* stats) {
  DeviceClipStats st;
  if (tb.beams.empty()) return {};
  std::vector<BeamPolygon> packed = pack(polygons);
  if (packed.empty()) packed.push_back(BeamPolygon{});  // no zero-sized buffers
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
    if (status[RTCL_BEAM_STATUS_PIECE_OVERFLOW] || status[RTCL_BEAM_STATUS_VERT_OVERFLOW]) {
      const Beam& t = tb.beams[std::min<std::size_t>(status[RTCL_BEAM_STATUS_FIRST_TILE], tb.beams.size() - 1)];
      throw Error("beam clipping: the beam at pixel (" + std::to_string(int(t.x0)) + ", " + std::to_string(int(t.y0)) +
                  ") " +
                  (status[RTCL_BEAM_STATUS_PIECE_OVERFLOW]
                       ? "needs more than " + std::to_string(RTCL_BEAM_MAX_PIECES) + " convex pieces"
                       : "has a piece of more than " + std::to_string(RTCL_BEAM_PIECE_VERTS) + " vertices") +
                  " (" + std::to_string(status[RTCL_BEAM_STATUS_PIECE_OVERFLOW] + status[RTCL_BEAM_STATUS_VERT_OVERFLOW]) +
                  " beams over the limit; RTCL_BEAM_MAX_PIECES / RTCL_BEAM_PIECE_VERTS in "
                  "kernels/shared/beam_layouts.h)");
    }
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
  std::sort(out.begin(), out.end(), [](const BeamFragment& a, const BeamFragment& b) {
    return a.beam != b.beam ? a.beam < b.beam : a.seq < b.seq;
  });
  st.fragments = out.size();
  if (stats) *stats = st;
  return out;
}

}  // namespace rtcl::beam
