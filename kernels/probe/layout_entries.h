/* Every record, field and size convention that crosses the host/device
 * boundary (kernels/shared/layouts.h, render_layouts.h, sampling.h, bounds_layouts.h), in
 * one list read by both kernels/probe/layout_probe.cl and
 * tests/layout_probe_test.cpp, which define the three entry kinds:
 *   RTCL_PROBE_RECORD(T)          sizeof(T) and the stride of a T array
 *   RTCL_PROBE_FIELD(T, member)   byte offset of a member designator
 *   RTCL_PROBE_SIZE(NAME, TYPE)   a host size constant NAME against the
 *                                 device's sizeof(TYPE)
 *   RTCL_PROBE_VALUE(EXPR)        a shared constant or macro result
 * A record added to a shared header is added here, or it is not proved. */

RTCL_PROBE_RECORD(Ray)
RTCL_PROBE_FIELD(Ray, ox) RTCL_PROBE_FIELD(Ray, oy) RTCL_PROBE_FIELD(Ray, oz)
RTCL_PROBE_FIELD(Ray, dx) RTCL_PROBE_FIELD(Ray, dy) RTCL_PROBE_FIELD(Ray, dz)
RTCL_PROBE_FIELD(Ray, tmin) RTCL_PROBE_FIELD(Ray, tmax)

RTCL_PROBE_RECORD(Hit)
RTCL_PROBE_FIELD(Hit, t) RTCL_PROBE_FIELD(Hit, u) RTCL_PROBE_FIELD(Hit, v) RTCL_PROBE_FIELD(Hit, prim)

RTCL_PROBE_RECORD(TriangleBlock)
RTCL_PROBE_FIELD(TriangleBlock, v) RTCL_PROBE_FIELD(TriangleBlock, v[1][0][0])
RTCL_PROBE_FIELD(TriangleBlock, v[0][1][0]) RTCL_PROBE_FIELD(TriangleBlock, v[2][2][7])
RTCL_PROBE_FIELD(TriangleBlock, prim)

RTCL_PROBE_RECORD(SphereBlock)
RTCL_PROBE_FIELD(SphereBlock, cx) RTCL_PROBE_FIELD(SphereBlock, cy) RTCL_PROBE_FIELD(SphereBlock, cz)
RTCL_PROBE_FIELD(SphereBlock, r) RTCL_PROBE_FIELD(SphereBlock, prim)

RTCL_PROBE_RECORD(Bvh8Node)
RTCL_PROBE_FIELD(Bvh8Node, bounds) RTCL_PROBE_FIELD(Bvh8Node, bounds[3][0])
RTCL_PROBE_FIELD(Bvh8Node, bounds[5][7]) RTCL_PROBE_FIELD(Bvh8Node, child)

RTCL_PROBE_RECORD(Bvh8Spheres)
RTCL_PROBE_FIELD(Bvh8Spheres, cx) RTCL_PROBE_FIELD(Bvh8Spheres, cy) RTCL_PROBE_FIELD(Bvh8Spheres, cz)
RTCL_PROBE_FIELD(Bvh8Spheres, r) RTCL_PROBE_FIELD(Bvh8Spheres, r[7])

RTCL_PROBE_RECORD(Bvh8Kdop)
RTCL_PROBE_FIELD(Bvh8Kdop, d_near) RTCL_PROBE_FIELD(Bvh8Kdop, d_near[3][7]) RTCL_PROBE_FIELD(Bvh8Kdop, d_far)

RTCL_PROBE_RECORD(Bvh8Obb)
RTCL_PROBE_FIELD(Bvh8Obb, axis) RTCL_PROBE_FIELD(Bvh8Obb, axis[8][7]) RTCL_PROBE_FIELD(Bvh8Obb, d_near)
RTCL_PROBE_FIELD(Bvh8Obb, d_far) RTCL_PROBE_FIELD(Bvh8Obb, d_far[2][7])
RTCL_PROBE_VALUE(RTCL_FILTER_REF(RTCL_FILTER_OBB, 5)) RTCL_PROBE_VALUE(RTCL_KDOP_FILTER_SLABS)

RTCL_PROBE_RECORD(GridHeader)
RTCL_PROBE_FIELD(GridHeader, lower) RTCL_PROBE_FIELD(GridHeader, cell) RTCL_PROBE_FIELD(GridHeader, res)
RTCL_PROBE_FIELD(GridHeader, res[2]) RTCL_PROBE_FIELD(GridHeader, macro)
RTCL_PROBE_FIELD(GridHeader, macro[3]) RTCL_PROBE_FIELD(GridHeader, lane_stride)
RTCL_PROBE_FIELD(GridHeader, occupied_bounds) RTCL_PROBE_FIELD(GridHeader, occupied_bounds[5][7])

RTCL_PROBE_RECORD(OctreeHeader)
RTCL_PROBE_FIELD(OctreeHeader, lower) RTCL_PROBE_FIELD(OctreeHeader, cell) RTCL_PROBE_FIELD(OctreeHeader, depth)
RTCL_PROBE_FIELD(OctreeHeader, leaf_count) RTCL_PROBE_FIELD(OctreeHeader, top_digits)

RTCL_PROBE_RECORD(BlockBox)
RTCL_PROBE_FIELD(BlockBox, bounds) RTCL_PROBE_FIELD(BlockBox, bounds[5])
RTCL_PROBE_RECORD(OctreeNode)
RTCL_PROBE_FIELD(OctreeNode, split) RTCL_PROBE_FIELD(OctreeNode, child) RTCL_PROBE_FIELD(OctreeNode, child[7])

RTCL_PROBE_RECORD(BottomLevel)
RTCL_PROBE_FIELD(BottomLevel, node_offset) RTCL_PROBE_FIELD(BottomLevel, triangle_offset)
RTCL_PROBE_FIELD(BottomLevel, sphere_offset)
RTCL_PROBE_RECORD(InstanceRecord)
RTCL_PROBE_FIELD(InstanceRecord, to_object) RTCL_PROBE_FIELD(InstanceRecord, to_object[8])
RTCL_PROBE_FIELD(InstanceRecord, translation) RTCL_PROBE_FIELD(InstanceRecord, bottom)
RTCL_PROBE_FIELD(InstanceRecord, user_id) RTCL_PROBE_FIELD(InstanceRecord, flags) RTCL_PROBE_FIELD(InstanceRecord, motion)
RTCL_PROBE_VALUE(RTCL_INSTANCE_LINEAR_IDENTITY) RTCL_PROBE_VALUE(RTCL_INSTANCE_MOVING)
RTCL_PROBE_VALUE(RTCL_INSTANCE_IDENTITY)
RTCL_PROBE_RECORD(InstanceMotion)
RTCL_PROBE_FIELD(InstanceMotion, open) RTCL_PROBE_FIELD(InstanceMotion, open[11]) RTCL_PROBE_FIELD(InstanceMotion, close)

RTCL_PROBE_RECORD(OctreePtrHeader)
RTCL_PROBE_FIELD(OctreePtrHeader, occupied_bounds) RTCL_PROBE_FIELD(OctreePtrHeader, occupied_bounds[5][7])
RTCL_PROBE_FIELD(OctreePtrHeader, lower) RTCL_PROBE_FIELD(OctreePtrHeader, upper)
RTCL_PROBE_FIELD(OctreePtrHeader, root) RTCL_PROBE_FIELD(OctreePtrHeader, leaf_count)
RTCL_PROBE_FIELD(OctreePtrHeader, depth) RTCL_PROBE_FIELD(OctreePtrHeader, pad)

RTCL_PROBE_VALUE(RTCL_OCTREE_MAX_DEPTH)
RTCL_PROBE_RECORD(KdNode)
RTCL_PROBE_FIELD(KdNode, flags) RTCL_PROBE_FIELD(KdNode, data)

RTCL_PROBE_RECORD(KdHeader)
RTCL_PROBE_FIELD(KdHeader, lower) RTCL_PROBE_FIELD(KdHeader, upper) RTCL_PROBE_FIELD(KdHeader, upper[2])
RTCL_PROBE_FIELD(KdHeader, lane_stride) RTCL_PROBE_FIELD(KdHeader, unused)

RTCL_PROBE_VALUE(RTCL_BLOCK_WIDTH)
RTCL_PROBE_VALUE(RTCL_CHILD_EMPTY)
RTCL_PROBE_VALUE(RTCL_LEAF_TRIANGLES(5))
RTCL_PROBE_VALUE(RTCL_LEAF_SPHERES(5))
RTCL_PROBE_VALUE(RTCL_KD_LEAF)
RTCL_PROBE_VALUE(RTCL_KD_INNER(2, 12345))
RTCL_PROBE_VALUE(RTCL_KD_LEAF_NODE(777))

RTCL_PROBE_RECORD(PathState)
RTCL_PROBE_FIELD(PathState, pixel) RTCL_PROBE_FIELD(PathState, depth)
RTCL_PROBE_FIELD(PathState, wr) RTCL_PROBE_FIELD(PathState, wg) RTCL_PROBE_FIELD(PathState, wb)

RTCL_PROBE_RECORD(DeviceMaterial)
RTCL_PROBE_FIELD(DeviceMaterial, ambient) RTCL_PROBE_FIELD(DeviceMaterial, diffuse)
RTCL_PROBE_FIELD(DeviceMaterial, specular) RTCL_PROBE_FIELD(DeviceMaterial, emission)
RTCL_PROBE_FIELD(DeviceMaterial, kr) RTCL_PROBE_FIELD(DeviceMaterial, kt)
RTCL_PROBE_FIELD(DeviceMaterial, kt[2]) RTCL_PROBE_FIELD(DeviceMaterial, shininess)
RTCL_PROBE_FIELD(DeviceMaterial, ior) RTCL_PROBE_FIELD(DeviceMaterial, roughness)

RTCL_PROBE_RECORD(DeviceLight)
RTCL_PROBE_FIELD(DeviceLight, position) RTCL_PROBE_FIELD(DeviceLight, radiance)
RTCL_PROBE_FIELD(DeviceLight, u) RTCL_PROBE_FIELD(DeviceLight, v) RTCL_PROBE_FIELD(DeviceLight, radius)
RTCL_PROBE_FIELD(DeviceLight, shape)

RTCL_PROBE_RECORD(DeviceCamera)
RTCL_PROBE_FIELD(DeviceCamera, origin) RTCL_PROBE_FIELD(DeviceCamera, corner)
RTCL_PROBE_FIELD(DeviceCamera, du) RTCL_PROBE_FIELD(DeviceCamera, dv)
RTCL_PROBE_FIELD(DeviceCamera, width) RTCL_PROBE_FIELD(DeviceCamera, height)
RTCL_PROBE_FIELD(DeviceCamera, lens_u) RTCL_PROBE_FIELD(DeviceCamera, lens_v)
RTCL_PROBE_FIELD(DeviceCamera, focus_distance) RTCL_PROBE_FIELD(DeviceCamera, sampler)
RTCL_PROBE_FIELD(DeviceCamera, seed) RTCL_PROBE_FIELD(DeviceCamera, filter)

RTCL_PROBE_RECORD(ShadeParams)
RTCL_PROBE_FIELD(ShadeParams, ambient) RTCL_PROBE_FIELD(ShadeParams, background)
RTCL_PROBE_FIELD(ShadeParams, min_weight) RTCL_PROBE_FIELD(ShadeParams, max_depth)
RTCL_PROBE_FIELD(ShadeParams, triangle_count) RTCL_PROBE_FIELD(ShadeParams, sampler)
RTCL_PROBE_FIELD(ShadeParams, seed) RTCL_PROBE_FIELD(ShadeParams, spp)
RTCL_PROBE_FIELD(ShadeParams, light_samples) RTCL_PROBE_FIELD(ShadeParams, shadow_slots)

RTCL_PROBE_RECORD(ShadeTriangle)
RTCL_PROBE_FIELD(ShadeTriangle, v) RTCL_PROBE_FIELD(ShadeTriangle, v[2][1])
RTCL_PROBE_FIELD(ShadeTriangle, material)

RTCL_PROBE_RECORD(ShadeSphere)
RTCL_PROBE_FIELD(ShadeSphere, center) RTCL_PROBE_FIELD(ShadeSphere, radius)
RTCL_PROBE_FIELD(ShadeSphere, material)

RTCL_PROBE_RECORD(ShadeInstance)
RTCL_PROBE_FIELD(ShadeInstance, open) RTCL_PROBE_FIELD(ShadeInstance, close)
RTCL_PROBE_FIELD(ShadeInstance, first_triangle) RTCL_PROBE_FIELD(ShadeInstance, first_sphere)
RTCL_PROBE_FIELD(ShadeInstance, triangle_count) RTCL_PROBE_FIELD(ShadeInstance, flags)

RTCL_PROBE_SIZE(RTCL_RADIANCE_BYTES, float4)
RTCL_PROBE_SIZE(RTCL_CHUNK_COUNT_BYTES, uint2)
RTCL_PROBE_SIZE(RTCL_FLAG_BYTES, uint)
RTCL_PROBE_VALUE(RTCL_SLOT_EMPTY)
RTCL_PROBE_VALUE(RTCL_SLOT_SHADOW)
RTCL_PROBE_VALUE(RTCL_SLOT_REFLECTION)
RTCL_PROBE_VALUE(RTCL_SLOT_REFRACTION)
RTCL_PROBE_VALUE(RTCL_SCAN_CHUNK)
RTCL_PROBE_VALUE(RTCL_TILE)
RTCL_PROBE_VALUE(rtcl_tile_order_pixel(77u, 13u, 11u))
RTCL_PROBE_VALUE(rtcl_hash(12345u))
RTCL_PROBE_VALUE(RTCL_LIGHT_POINT) RTCL_PROBE_VALUE(RTCL_LIGHT_QUAD) RTCL_PROBE_VALUE(RTCL_LIGHT_DISC)
RTCL_PROBE_VALUE(RTCL_LIGHT_SPHERE) RTCL_PROBE_VALUE(RTCL_LIGHT_TRIANGLE)
RTCL_PROBE_VALUE(RTCL_SAMPLER_STRATIFIED) RTCL_PROBE_VALUE(RTCL_SAMPLER_RANDOM) RTCL_PROBE_VALUE(RTCL_SAMPLER_SOBOL)
RTCL_PROBE_VALUE(RTCL_FILTER_BOX) RTCL_PROBE_VALUE(RTCL_FILTER_GAUSSIAN)
RTCL_PROBE_VALUE(rtcl_dimension_light(3u, 2u, 1u)) RTCL_PROBE_VALUE(rtcl_dimension_glossy(3u, 2u))
RTCL_PROBE_VALUE(rtcl_owen_scramble(0x9e3779b9u, 77u)) RTCL_PROBE_VALUE(rtcl_sobol_second(12345u))
RTCL_PROBE_VALUE(rtcl_reverse_bits(12345u)) RTCL_PROBE_VALUE(rtcl_permute(5u, 11u, 99u))
RTCL_PROBE_VALUE(rtcl_mix_bits(5u, 4u, 99u)) RTCL_PROBE_VALUE(rtcl_sample_key(1u, 2u, 3u, 4u))
RTCL_PROBE_VALUE(rtcl_ceil_sqrt(2147395600u)) RTCL_PROBE_VALUE(rtcl_ceil_sqrt(2147395601u))
RTCL_PROBE_VALUE(rtcl_ceil_sqrt(1u)) RTCL_PROBE_VALUE(rtcl_ceil_sqrt(24u))

RTCL_PROBE_RECORD(SlabVolume)
RTCL_PROBE_FIELD(SlabVolume, normal) RTCL_PROBE_FIELD(SlabVolume, normal[12][3])
RTCL_PROBE_FIELD(SlabVolume, d_near) RTCL_PROBE_FIELD(SlabVolume, d_far) RTCL_PROBE_FIELD(SlabVolume, d_far[15])
RTCL_PROBE_FIELD(SlabVolume, reach) RTCL_PROBE_FIELD(SlabVolume, count)
RTCL_PROBE_RECORD(SphereVolume)
RTCL_PROBE_FIELD(SphereVolume, cx) RTCL_PROBE_FIELD(SphereVolume, r) RTCL_PROBE_FIELD(SphereVolume, reach)
RTCL_PROBE_VALUE(RTCL_MAX_SLABS)
RTCL_PROBE_VALUE(RTCL_SLAB_ROW)

RTCL_PROBE_RECORD(BeamPolygon)
RTCL_PROBE_FIELD(BeamPolygon, x) RTCL_PROBE_FIELD(BeamPolygon, y) RTCL_PROBE_FIELD(BeamPolygon, inv_depth)
RTCL_PROBE_FIELD(BeamPolygon, count)
RTCL_PROBE_RECORD(Beam)
RTCL_PROBE_FIELD(Beam, y) RTCL_PROBE_FIELD(Beam, x0) RTCL_PROBE_FIELD(Beam, y0) RTCL_PROBE_FIELD(Beam, vertex_count)
RTCL_PROBE_FIELD(Beam, first) RTCL_PROBE_FIELD(Beam, count)
RTCL_PROBE_RECORD(BeamFragment)
RTCL_PROBE_FIELD(BeamFragment, beam) RTCL_PROBE_FIELD(BeamFragment, polygon) RTCL_PROBE_FIELD(BeamFragment, count) RTCL_PROBE_FIELD(BeamFragment, x)
RTCL_PROBE_FIELD(BeamFragment, y) RTCL_PROBE_FIELD(BeamFragment, y[15])
RTCL_PROBE_VALUE(RTCL_BEAM_POLYGON_VERTS) RTCL_PROBE_VALUE(RTCL_BEAM_PIECE_VERTS)
RTCL_PROBE_VALUE(RTCL_BEAM_MAX_PIECES) RTCL_PROBE_VALUE(RTCL_BEAM_STATUS_WORDS)
