// A kind of light (point, spot, directional, IES profile) in one place: what every stage asks of it, after pbrt's Light and
// Filament's driver table. A light's data stays a plain `Light` (scene/scene.h); its kind answers
//   - the walk:       its radiant intensity, its power and the rays that leave it (emission);
//   - the transport:  its direct term at a point, before the shadow test (visibility is the caller's);
//   - the stages:     the vector towards it, whether it lies at infinity, its influence bound;
//   - the probes:     the delta it adds to a probe's SH projection (atNormalIncidence);
//   - real time:      its KHR_lights_punctual fields, the shadow map the GL backend renders for it and the
//                     uniforms its shaders read (the same for the bake's direct pass and irview's mixed lights).
// lightKind(type) finds a kind in the registry (light_kinds.cpp), a table indexed by LightType. A new kind is
// its own file plus a row there (and its LightType value and its name in the glTF loader).
#pragma once
#include <nlohmann/json.hpp>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake {

// A punctual light at a receiver, before the shadow test.
struct PunctualContribution {
  glm::vec3 mapValue{0.0f};     // irradiance / π if visible (0: nothing to trace)
  glm::vec3 toLight{0.0f};      // unit direction from the receiver towards the light
  float distance = 0.0f;        // to the light; infinity for lights at infinity
};

// The shadow map the GL backend renders for a light (bake_interface.glsl's BAKE_SHADOW_* codes).
enum class ShadowProjection { Cube, Perspective, Orthographic };

// What the light-map and viewer shaders read for one light: its shader code (bake_interface.glsl's
// BAKE_LIGHT_*; irview's mixed lights use the same codes), RGB intensity and the cone's falloff terms.
struct ShaderLight {
  int code = 0;
  glm::vec3 intensity{0.0f};  // colour × intensity (W/sr, or W/m² at infinity)
  float cosOuter = 0.0f;      // cos of the outer cone angle
  float spotScale = 0.0f;     // 1 / (cos inner − cos outer), the band at least 0.001
};

class LightKind {
 public:
  virtual ~LightKind() = default;

  // KHR_lights_punctual's type name ("point", "spot", "directional"), or "ies" (EXT_lights_ies).
  virtual const char* name() const = 0;
  // True for a light at infinity (a direction, no position): rays towards it never end.
  virtual bool atInfinity() const = 0;
  // True when the light has a direction worth writing (spot, directional).
  virtual bool aimed() const = 0;

  // Radiant intensity (W/sr, RGB) towards a unit direction leaving the light.
  virtual glm::vec3 intensityToward(const Light& light, const glm::vec3& dirFromLight) const = 0;
  // Total emitted power (W, RGB); 0 for a light at infinity.
  virtual glm::vec3 power(const Light& light) const = 0;
  // The power the walk gives the light's paths: its power, or for a light at infinity what crosses the disc of
  // the scene's bounding sphere (radius sceneRadius).
  virtual glm::dvec3 walkPower(const Light& light, float sceneRadius) const = 0;
  // A ray leaving the light for the walk's random numbers (u0, u1: a point, u2, u3: a direction), distributed
  // like its intensity so every path carries the same power; returns the path's weight against that power
  // (I(ω) / (p(ω) · power), 1 where the rays follow the intensity exactly). Rays of a light at infinity start
  // on a disc covering the scene's bounding sphere (sceneCentre, sceneRadius), upstream of it.
  virtual double emit(const Light& light, const glm::vec3& sceneCentre, float sceneRadius, double u0, double u1,
                    double u2, double u3, glm::vec3& origin, glm::vec3& dir) const = 0;

  // From x towards the light: light position − x, or −direction for a light at infinity (not normalised).
  virtual glm::vec3 toward(const Light& light, const glm::vec3& x) const = 0;
  // The light at a receiver (x, unit normal nx), visibility left to the caller (transport/geometry_term.h).
  virtual PunctualContribution direct(const Light& light, const glm::vec3& x, const glm::vec3& nx) const = 0;
  // False where the light cannot give x more than `threshold` (W/m², on the axis, facing it): beyond its
  // range, its reach at that threshold or its cone. Lights at infinity reach everywhere.
  virtual bool influences(const Light& light, const glm::vec3& x, float threshold) const = 0;

  // Its glTF light object's "type" and the fields of that type (KHR_lights_punctual; EXT_lights_ies: its profile
  // object, whose uri the writer sets).
  virtual void describeGltf(const Light& light, nlohmann::json& gltfLight) const = 0;
  // The shadow map the GL backend renders: spots wider than maxPerspectiveAngle take a cube.
  virtual ShadowProjection shadowProjection(const Light& light, float maxPerspectiveAngle) const = 0;
  // The shader's code for this kind.
  virtual int shaderCode() const = 0;

  // The uniforms of shaderCode() and the light's data.
  ShaderLight shaderLight(const Light& light) const;
  // The light at p on a surface facing it: the delta (toLight, mapValue) a probe's SH projection adds; zero when
  // p has no direction towards the light.
  PunctualContribution atNormalIncidence(const Light& light, const glm::vec3& p) const;
};

// The kind of a light type (registry: light_kinds.cpp).
const LightKind& lightKind(LightType type);
inline const LightKind& lightKind(const Light& light) { return lightKind(light.type); }

}  // namespace irbake
