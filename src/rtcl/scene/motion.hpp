// Moving objects (motion blur; Cook, Porter & Carpenter 1984): keyframe
// time 0 is an object's `transform` (a sphere's centre and radius), keyframe
// time 1 its end keyframe (SceneMesh::end_transform, SceneSphere::end_*).
// At time t a mesh's object-to-world transform is the blend
// (1 - t) * transform + t * end_transform, so each vertex moves on a straight
// line at constant speed, and a sphere's centre and radius move linearly.
// Rotations are blended as matrices, not as rotations: a large rotation
// shrinks the object in between (180 degrees flattens it: refused).
#pragma once

#include <glm/glm.hpp>

#include "rtcl/scene/scene_description.hpp"

namespace rtcl {

// Whether some mesh or sphere has an end keyframe (even one equal to its
// start: the renderer then takes the moving path).
bool scene_moves(const SceneDescription& scene);

// The mesh's object-to-world transform at keyframe time `time`.
glm::dmat4 transform_at(const SceneMesh& mesh, double time);
// The sphere at keyframe time `time` (static: itself).
SceneSphere sphere_at(const SceneSphere& sphere, double time);

// The static scene of every object at keyframe time `time` (end keyframes
// dropped); flatten() of it is the world-space geometry at that time.
SceneDescription scene_at(const SceneDescription& scene, double time);

// Whether det((1 - t) * open + t * close) keeps the sign of its value at t0,
// never reaching zero (within rounding of its scale), for t in [t0, t1]:
// a blend of the two linear maps that never collapses space onto a plane.
// The cubic's sign at both ends and at its critical points inside decides,
// since it is monotone between them.
bool blend_keeps_determinant_sign(const glm::dmat3& open, const glm::dmat3& close, double t0, double t1);

// Throws Error naming the object's motion key when a moving mesh's blended
// transform is singular (its determinant vanishes or changes sign: the mesh
// collapses onto a plane) or a moving sphere's radius is not positive at
// some time of [t0, t1]; and naming camera.shutter when the interval is not
// finite or t0 > t1.
void check_motion(const SceneDescription& scene, double t0, double t1);

}  // namespace rtcl
