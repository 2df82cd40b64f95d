// Compile-time proof that the host sees the bounding-volume records
// (kernels/shared/bounds_layouts.h) with the sizes and offsets the kernels use.
#include "rtcl/bounds/bounds_layouts.hpp"

#include <cstddef>

namespace rtcl {

static_assert(RTCL_SLAB_ROW >= RTCL_MAX_SLABS && RTCL_SLAB_ROW % 4 == 0);
static_assert(sizeof(SlabVolume) == 352 && alignof(SlabVolume) == 4);
static_assert(offsetof(SlabVolume, d_near) == 208 && offsetof(SlabVolume, d_far) == 272 &&
              offsetof(SlabVolume, reach) == 336 && offsetof(SlabVolume, count) == 340);
static_assert(sizeof(SphereVolume) == 32 && offsetof(SphereVolume, r) == 12 && offsetof(SphereVolume, reach) == 16);

}  // namespace rtcl
