// Volume and surface area of a slab volume (AABB, OBB, k-DOP as a
// SlabVolume): each of the 2 * count planes is cut to its face polygon by
// the other half-spaces (convex polygon clipping, in double), the area is
// the sum of the faces, the volume the sum of the cones from an interior
// point to the faces (divergence theorem). A flat volume (a slab of zero
// width) has volume 0 and the area of both sides.
#pragma once

#include "rtcl/bounds/bounds_layouts.hpp"

namespace rtcl {

struct VolumeMeasure {
  double volume = 0.0;  // world units^3
  double area = 0.0;    // world units^2
};

// count = 0 (empty) measures 0. The slabs must bound a finite region (every
// direction set of kdop.hpp and every OBB does).
VolumeMeasure measure_slabs(const SlabVolume& v);

}  // namespace rtcl
