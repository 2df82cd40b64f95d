/* Ray tests of one bounding volume for a batch of rays (shared/volumes.h):
 * hit[i] = 1 when ray i may meet the contents, t_entry[i] its entry
 * distance (+inf on a miss). Used by tests/bounds_rays_test.cpp and the
 * bounds benchmark. */
#include "shared/layouts.h"
#include "shared/volumes.h"

kernel void intersect_slab_volume_rays(global const SlabVolume* volume, global const Ray* rays, uint count,
                                       global int* hit, global float* t_entry) {
  uint i = get_global_id(0);
  if (i >= count) return;
  Ray r = rays[i];
  float t = INFINITY;
  int h = intersect_slab_volume(volume, &r, &t);
  hit[i] = h;
  t_entry[i] = h ? t : INFINITY;
}

kernel void intersect_sphere_volume_rays(global const SphereVolume* volume, global const Ray* rays, uint count,
                                         global int* hit, global float* t_entry) {
  uint i = get_global_id(0);
  if (i >= count) return;
  Ray r = rays[i];
  float t = INFINITY;
  int h = intersect_sphere_volume(volume, &r, &t);
  hit[i] = h;
  t_entry[i] = h ? t : INFINITY;
}
