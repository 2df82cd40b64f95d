// Compile-time proof that the host sees the renderer's device records
// (kernels/shared/render_layouts.h) with the sizes and offsets the kernels use.
#include "rtcl/render/render_layouts.hpp"

#include <cstddef>

namespace rtcl {

static_assert(sizeof(PathState) == 20 && alignof(PathState) == 4);
static_assert(offsetof(PathState, depth) == 4 && offsetof(PathState, wr) == 8 && offsetof(PathState, wb) == 16);
static_assert(sizeof(DeviceMaterial) == 84 && offsetof(DeviceMaterial, kr) == 48 &&
              offsetof(DeviceMaterial, shininess) == 72 && offsetof(DeviceMaterial, ior) == 76 &&
              offsetof(DeviceMaterial, roughness) == 80);
static_assert(sizeof(DeviceLight) == 56 && offsetof(DeviceLight, radiance) == 12 && offsetof(DeviceLight, u) == 24 &&
              offsetof(DeviceLight, v) == 36 && offsetof(DeviceLight, radius) == 48 && offsetof(DeviceLight, shape) == 52);
static_assert(sizeof(DeviceCamera) == 96 && offsetof(DeviceCamera, dv) == 36 && offsetof(DeviceCamera, width) == 48 &&
              offsetof(DeviceCamera, lens_u) == 56 && offsetof(DeviceCamera, lens_v) == 68 &&
              offsetof(DeviceCamera, focus_distance) == 80 && offsetof(DeviceCamera, sampler) == 84 &&
              offsetof(DeviceCamera, seed) == 88 && offsetof(DeviceCamera, filter) == 92);
static_assert(sizeof(ShadeParams) == 56 && offsetof(ShadeParams, min_weight) == 24 &&
              offsetof(ShadeParams, triangle_count) == 32 && offsetof(ShadeParams, sampler) == 36 &&
              offsetof(ShadeParams, seed) == 40 && offsetof(ShadeParams, spp) == 44 &&
              offsetof(ShadeParams, light_samples) == 48 && offsetof(ShadeParams, shadow_slots) == 52);
static_assert(sizeof(ShadeTriangle) == 40 && offsetof(ShadeTriangle, material) == 36);
static_assert(sizeof(ShadeSphere) == 20 && offsetof(ShadeSphere, radius) == 12 && offsetof(ShadeSphere, material) == 16);
static_assert(sizeof(ShadeInstance) == 112 && offsetof(ShadeInstance, close) == 48 &&
              offsetof(ShadeInstance, first_triangle) == 96 && offsetof(ShadeInstance, first_sphere) == 100 &&
              offsetof(ShadeInstance, triangle_count) == 104 && offsetof(ShadeInstance, flags) == 108);

static_assert(RTCL_RADIANCE_BYTES == 4 * sizeof(float) && RTCL_CHUNK_COUNT_BYTES == 2 * sizeof(rtcl_u32) &&
              RTCL_FLAG_BYTES == sizeof(rtcl_u32));

}  // namespace rtcl
