#include "rtcl/beam/beam_clip_host.hpp"

namespace rtcl::beam {

Convex cross_section(const Beam& b) {
  Convex c;
  for (std::uint32_t k = 0; k < b.vertex_count && k < RTCL_BEAM_PIECE_VERTS; ++k) c.v.push_back({b.x[k], b.y[k]});
  return c;
}

std::vector<HostFragment> clip_beams_host(const std::vector<ScreenPolygon>& polygons, const BeamSet& tb,
                                          DepthOrder order) {
  std::vector<HostFragment> out;
  for (std::uint32_t ti = 0; ti < tb.beams.size(); ++ti) {
    const Beam& t = tb.beams[ti];
    Region beam{cross_section(t)};
    const double min_area = beam_min_area_fraction * area(beam);
    for (std::uint32_t c = 0; c < t.count && !beam.empty(); ++c) {
      const ScreenPolygon& p = polygons[tb.candidates[t.first + c]];
      const Convex poly{p.v};
      Region next;
      for (const Convex& b : beam) {
        Convex f = intersect(b, poly);
        if (f.v.size() < 3 || signed_area(f.v) < min_area) {
          next.push_back(b);
          continue;
        }
        Region kept{f};
        bool gave_up = false;
        if (order == DepthOrder::exact)
          for (std::uint32_t l = c + 1; l < t.count && !kept.empty(); ++l) {
            const ScreenPolygon& q = polygons[tb.candidates[t.first + l]];
            glm::dvec3 d = q.inv_depth - p.inv_depth;  // > 0 where q is nearer
            Convex front = clip(Convex{q.v}, HalfPlane{d.x, d.y, d.z});
            if (front.v.size() < 3) continue;
            Region r = subtract(kept, front, min_area);
            if (area(r) != area(kept)) gave_up = true;
            kept = std::move(r);
          }
        for (Convex& piece : kept) out.push_back({ti, tb.candidates[t.first + c], piece});
        Region rest = subtract(b, poly, min_area);
        next.insert(next.end(), rest.begin(), rest.end());
        if (gave_up) {
          Region back = subtract(Region{f}, kept, min_area);  // f's part where later polygons are nearer
          next.insert(next.end(), back.begin(), back.end());
        }
      }
      beam = std::move(next);
    }
  }
  return out;
}

}  // namespace rtcl::beam
