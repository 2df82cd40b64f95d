// The scene model of the renderer: a pinhole or thin-lens camera, point and
// area lights, Phong
// materials with Whitted reflection/refraction, triangle meshes with
// per-object transforms and analytic spheres; and its flattening into the
// Geometry the acceleration structures are built over, with one material per
// primitive. Units: lengths in scene units, angles in degrees, colours linear
// RGB.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "rtcl/precision.hpp"

#include "rtcl/geometry.hpp"

namespace rtcl {

struct Material {
  std::string name;
  glm::vec3 ambient{0.0f};   // multiplied by SceneDescription::ambient
  glm::vec3 diffuse{0.8f};   // Lambert term per light
  glm::vec3 specular{0.0f};  // Phong term per light: specular * max(0, R.V)^shininess
  float shininess = 32.0f;   // Phong exponent, >= 0
  glm::vec3 emission{0.0f};  // added where a ray hits the surface
  glm::vec3 kr{0.0f};        // mirror reflectance, each in [0, 1]
  glm::vec3 kt{0.0f};        // transmittance, each in [0, 1]; Fresnel splits it into reflection and refraction
  float ior = 1.5f;          // index of refraction inside the surface (> 0; outside is 1)
  // 0: the reflected ray is the mirror direction; in (0, 1]: it is drawn from
  // the Phong lobe of exponent 2 / roughness^2 - 2 around it (glossy).
  float roughness = 0.0f;

  bool reflective() const { return glm::any(glm::greaterThan(kr, glm::vec3(0.0f))); }
  bool transmissive() const { return glm::any(glm::greaterThan(kt, glm::vec3(0.0f))); }
  bool glossy() const { return roughness > 0.0f && (reflective() || transmissive()); }
};

// emissive: every triangle whose material has emission > 0 lights the scene
// (expand_emissive_lights turns it into one triangle light per triangle).
enum class LightShape { point, quad, disc, sphere, emissive, triangle };

// A light. An area light (quad, disc, sphere, triangle) is the average of
// point lights of its radiance over its points, uniformly by area (a sphere:
// over the disc through its centre that faces the shaded point): soft
// shadows, and a light of size zero is the point light. An emissive light's
// radiance at a triangle's point is the triangle's emission times color times
// intensity.
struct Light {
  glm::vec3 position{0.0f};  // point: the point; quad, disc, sphere: the centre; triangle: a corner
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // radiance = color * intensity, no distance falloff
  LightShape shape = LightShape::point;
  glm::vec3 edge1{0.0f}, edge2{0.0f};  // quad: its two edge vectors (full lengths); triangle: from the corner
  glm::vec3 normal{0.0f, -1.0f, 0.0f};  // disc: its normal (non-zero; either side lights alike)
  float radius = 0.0f;                  // disc, sphere: >= 0
  bool area() const { return shape != LightShape::point; }
};
using PointLight = Light;

struct Camera {
  glm::vec3 position{0.0f, 0.0f, 5.0f};
  glm::vec3 look_at{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_deg = 45.0f;  // vertical field of view, in (0, 180)
  float aspect = 0.0f;    // width / height the scene is framed for; 0: none (the image decides)
  // Thin lens: radius of the aperture (scene units, >= 0; 0 is the pinhole)
  // and the distance along the view direction that is in focus (> 0; 0
  // here: the distance to look_at).
  float aperture = 0.0f;
  float focus_distance = 0.0f;
  // Shutter interval on the keyframe time axis of moving objects (keyframe
  // 0 at time 0, keyframe 1 at time 1; open <= close, finite). Each ray's
  // time is drawn uniformly from it (motion blur); it matters only where an
  // object moves.
  float shutter_open = 0.0f, shutter_close = 1.0f;
};

// A triangle mesh's data in object space. Scene objects that load the same
// mesh file with the same material assignment share one MeshShape (a
// std::shared_ptr): the renderer then builds it once and places it by
// instances (docs/scenes-and-instances.md, "Scene files and the renderer").
struct MeshShape {
  std::vector<glm::vec3> vertices;
  std::vector<glm::uvec3> triangles;
  std::vector<std::uint32_t> materials;  // one per triangle, index into SceneDescription::materials
};

// A triangle mesh: its shape (object space, possibly shared with other
// meshes) and its object-to-world transform.
struct SceneMesh {
  std::string name;  // the file path or a built-in name: named in errors
  std::shared_ptr<const MeshShape> shape = std::make_shared<const MeshShape>();  // never null
  glm::dmat4 transform{1.0};             // object to world; a mirroring one keeps faces outward
  // Motion: the object-to-world transform at keyframe time 1 (`transform`
  // is keyframe 0); at time t the transform is the blend (1 - t) * transform
  // + t * end_transform, so every vertex moves on a straight line at
  // constant speed, beyond [0, 1] too (rtcl/scene/motion.hpp). None: static.
  std::optional<glm::dmat4> end_transform;
  std::string motion_key;  // where the motion was given ("scene.json: objects[2].motion"): named in errors

  // The shape's data (shorthands).
  const std::vector<glm::vec3>& vertices() const { return shape->vertices; }
  const std::vector<glm::uvec3>& triangles() const { return shape->triangles; }
  const std::vector<std::uint32_t>& materials() const { return shape->materials; }
  // This mesh's own copy of its shape to change: the shape is copied first,
  // so the meshes that shared it keep theirs.
  MeshShape& edit_shape() {
    auto copy = std::make_shared<MeshShape>(*shape);
    MeshShape& out = *copy;
    shape = std::move(copy);
    return out;
  }
};

// A sphere in world space (spheres are transformed when loaded).
struct SceneSphere {
  glm::dvec3 center{0.0};
  double radius = 1.0;
  std::uint32_t material = 0;
  // Motion: centre and radius at keyframe time 1 (center, radius: keyframe
  // 0); both move linearly in time. Only when `moving`.
  bool moving = false;
  glm::dvec3 end_center{0.0};
  double end_radius = 1.0;
  std::string motion_key;  // as SceneMesh::motion_key

  // A sphere that does not move.
  static SceneSphere still(glm::dvec3 center, double radius, std::uint32_t material) {
    SceneSphere s;
    s.center = center;
    s.radius = radius;
    s.material = material;
    return s;
  }
};

struct SceneDescription {
  std::string source = "scene";  // the scene file, or "default scene": named in errors
  Camera camera;
  glm::vec3 ambient{0.0f};     // ambient light
  glm::vec3 background{0.0f};  // radiance of rays that leave the scene
  std::vector<Light> lights;
  std::vector<Material> materials;
  std::vector<SceneMesh> meshes;
  std::vector<SceneSphere> spheres;
  std::vector<std::string> notes;  // things the user should know (mesh loader quirks), never errors
  // "precision" of the scene file: the trace kernels' level and the spawn
  // offsets (rtcl render --precision overrides it); none: robust.
  std::optional<Precision> precision;
  // "accel" of the scene file as a structure spec ("grid:lambda=4",
  // rtcl/accel_options.hpp), checked when read: the structure rtcl render
  // builds unless --accel is given. "" when the file names none.
  std::string accel;
};

// Throws Error naming scene.source and the element for: a degenerate camera
// (position = look_at, up parallel to the view, fov outside (0, 180), a
// negative aperture or focus distance), a negative colour, intensity or light
// radius, a disc light without a normal, kr/kt/roughness outside [0, 1],
// ior <= 0, a negative shininess, a material index out of range, a non-finite number anywhere,
// or a scene with no mesh and no sphere.
void validate(const SceneDescription& scene);

// Whether some MeshShape is the shape of more than one mesh: the renderer
// then traces the scene through instances (Renderer).
bool shares_meshes(const SceneDescription& scene);
// The scene with every mesh holding its own copy of its shape (no sharing):
// the same image through the renderer's flat path.
SceneDescription unshare_meshes(const SceneDescription& scene);

// The world-space primitives: mesh triangles in mesh order (transformed in
// double, rounded to float), then spheres; material[prim] for every
// primitive id. Geometry::source is scene.source.
struct FlatScene {
  Geometry geometry;
  std::vector<std::uint32_t> material;
};
FlatScene flatten(const SceneDescription& scene);

// scene.lights with each emissive light replaced by one triangle light per
// emitting triangle of `flat` (in primitive order), each of radiance emission
// * color * intensity times its share of the emitters' total area (so that
// together they are the average over the emitters' points). Throws Error
// naming the light when no triangle emits.
std::vector<Light> expand_emissive_lights(const SceneDescription& scene, const FlatScene& flat);

// The scene moved by a similarity transform (rotation, uniform scale,
// translation): camera, lights, meshes and spheres. Throws Error when
// `transform` is not a similarity. For scale and translation tests.
SceneDescription transform_scene(const SceneDescription& scene, const glm::dmat4& transform);

// The uniform scale of a similarity transform; throws Error naming `what`
// when the 3x3 part is not a rotation times a positive scale.
double similarity_scale(const glm::dmat4& transform, const std::string& what);

}  // namespace rtcl
