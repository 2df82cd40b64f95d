// Compile-time proof that the host sees the beam tracer's device records
// (kernels/shared/beam_layouts.h) with the sizes and offsets the kernels use.
#include "rtcl/beam/beam_layouts.hpp"

#include <cstddef>

namespace rtcl {

static_assert(sizeof(BeamPolygon) == 80 && alignof(BeamPolygon) == 4);
static_assert(offsetof(BeamPolygon, y) == 32 && offsetof(BeamPolygon, inv_depth) == 64 &&
              offsetof(BeamPolygon, count) == 76);
static_assert(sizeof(Beam) == 148 && offsetof(Beam, y) == 64 && offsetof(Beam, x0) == 128 &&
              offsetof(Beam, vertex_count) == 136 && offsetof(Beam, first) == 140 && offsetof(Beam, count) == 144);
static_assert(sizeof(BeamFragment) == 144 && offsetof(BeamFragment, count) == 12 && offsetof(BeamFragment, x) == 16 &&
              offsetof(BeamFragment, y) == 80);

}  // namespace rtcl
