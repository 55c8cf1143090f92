#pragma once
// Surface shading: materials, a key/fill/rim light rig, Lambert and
// Blinn-Phong, a ground plane with a grid and a soft contact shadow, and the
// background gradient. All colours are linear RGB; all vectors world space.

#include <span>

#include <glm/glm.hpp>

#include "deform/mesh.h"

namespace render {

// How a surface's normal is chosen.
enum class ShadingMode {
  kSmooth,  // perspective-correct interpolation of the vertex normals
  kFlat,    // the triangle's geometric normal
};

// Which lighting equation is evaluated.
enum class LightingModel {
  kUnlit,       // colour as given (for tests and id-like renders)
  kLambert,     // ambient + key light diffuse only (the cheapest lit model)
  kBlinnPhong,  // ambient + key/fill/rim diffuse + Blinn-Phong specular
};

// A directional light fixed to the camera, so a turntable keeps its look.
struct DirectionalLight {
  glm::vec3 direction_view{0.0f, 0.0f, 1.0f};  // towards the light, view space (normalized on use)
  glm::vec3 color{1.0f};                       // linear RGB radiance scale
  float intensity = 1.0f;                      // multiplies color, >= 0
};

struct LightRig {
  DirectionalLight key{{-0.45f, 0.6f, 0.65f}, {1.0f, 0.97f, 0.92f}, 0.95f};
  DirectionalLight fill{{0.6f, 0.1f, 0.6f}, {0.8f, 0.87f, 1.0f}, 0.3f};
  DirectionalLight rim{{0.1f, 0.5f, -0.85f}, {1.0f, 1.0f, 1.0f}, 0.45f};
  glm::vec3 ambient{0.12f, 0.13f, 0.15f};  // added to every lit surface (times albedo)
  float specular = 0.25f;                   // Blinn-Phong specular weight, >= 0
  float shininess = 32.0f;                  // Blinn-Phong exponent, > 0
};

// The ground plane y = height (world), drawn under the scene.
struct GroundStyle {
  glm::vec3 color{0.55f, 0.56f, 0.58f};       // albedo between grid lines
  glm::vec3 line_color{0.35f, 0.36f, 0.38f};  // albedo of grid lines
  float grid_spacing = 0.0f;       // world units between lines; 0 = 1/4 of the scene height
  float line_width = 0.03f;        // line width as a fraction of grid_spacing
  float shadow_strength = 0.6f;    // darkening at the centre of the contact shadow, 0..1
  float fade_start = 12.0f;        // grid spacings from the eye where lines start to fade, > 0
};

struct Background {
  glm::vec3 top{0.32f, 0.36f, 0.42f};     // colour of the first image row
  glm::vec3 bottom{0.10f, 0.11f, 0.13f};  // colour of the last image row
  bool transparent = false;  // true: alpha = coverage and no gradient is drawn
};

// A soft elliptical darkening of the ground under one object: full strength
// at the centre falling off as a Gaussian of the normalized radial distance.
struct ContactShadow {
  glm::vec2 centre_xz{0.0f};  // world xz of the centre
  glm::vec2 radius_xz{1.0f};  // world half-axes, > 0
  float strength = 0.6f;      // 0..1
};

// Per-frame shading state: light directions resolved to world space.
struct ShadingContext {
  LightingModel model = LightingModel::kBlinnPhong;
  glm::vec3 eye{0.0f};  // world-space camera position
  glm::vec3 key_dir{0.0f, 0.0f, 1.0f}, fill_dir{0.0f, 0.0f, 1.0f}, rim_dir{0.0f, 0.0f, 1.0f};
  glm::vec3 key_radiance{1.0f}, fill_radiance{0.0f}, rim_radiance{0.0f};
  glm::vec3 ambient{0.0f};
  float specular = 0.0f;
  float shininess = 32.0f;
};

// Resolves `rig` (view-space lights) with the camera's world_from_view rotation.
ShadingContext MakeShadingContext(const LightRig& rig, LightingModel model,
                                  const glm::mat4& view_from_world);

// Lit colour of a surface point. `normal` must be unit length and face the
// viewer side the caller wants lit; `position` is only used for specular;
// `key_visibility` scales the key light (its shadow map's verdict, 1 = lit).
glm::vec3 ShadeSurface(const ShadingContext& ctx, const glm::vec3& albedo,
                       const glm::vec3& normal, const glm::vec3& position,
                       float key_visibility = 1.0f);

// Ground albedo at world point `position` (grid lines blended in), before
// lighting. Lines fade out between style.fade_start and 2 * style.fade_start
// grid spacings from `eye`, where they would be thinner than a pixel and alias.
glm::vec3 GroundAlbedo(const GroundStyle& style, float grid_spacing, const glm::vec3& position,
                       const glm::vec3& eye);

// Multiplier in [1 - max strength, 1] from the contact shadows at `position`.
float ContactShadowFactor(std::span<const ContactShadow> shadows, const glm::vec3& position);

// A contact shadow matching the footprint of `bounds` on the ground at `ground_y`;
// its strength fades as the object rises above the ground.
ContactShadow ShadowUnder(const deform::Bounds& bounds, float ground_y, float strength);

// Background colour for a row at normalized height t (0 = top, 1 = bottom).
glm::vec3 BackgroundColor(const Background& background, float t);

}  // namespace render
