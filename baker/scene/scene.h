// The scene model every stage reads: world-space triangles, materials, textures, lights, cameras.
// Units: metres; radiometric quantities in watts (see docs/units.md).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/environment.h"
#include "scene/ies_profile.h"

namespace irbake {

struct Bounds3 {
  glm::vec3 min{1e30f};
  glm::vec3 max{-1e30f};
  void extend(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
  void extend(const Bounds3& b) { min = glm::min(min, b.min); max = glm::max(max, b.max); }
  bool valid() const { return min.x <= max.x && min.y <= max.y && min.z <= max.z; }
  glm::vec3 extent() const { return valid() ? max - min : glm::vec3(0.0f); }
  float diagonal() const { return glm::length(extent()); }
};

enum class WrapMode { Repeat, ClampToEdge, MirroredRepeat };
enum class AlphaMode { Opaque, Mask, Blend };

// A decoded image, linear RGBA float (colour textures are sRGB-decoded at load).
struct Texture {
  std::string name;           // image name or URI, for messages
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // row-major, row 0 = top of the image (glTF UV v=0)
  WrapMode wrapS = WrapMode::Repeat, wrapT = WrapMode::Repeat;
  int gltfImage = -1;         // source image index in the glTF
};

// KHR_texture_transform on a texture reference: uv' = offset + R · (scale ⊙ uv), the specification's
// translation × rotation × scale, where R turns the UVs by `rotation` radians counter-clockwise:
// u' = cos·u + sin·v, v' = −sin·u + cos·v (its example: offset (0, 1), rotation π/2, scale ½ reads the
// image's lower-left quadrant). The identity when the extension is absent.
struct UvTransform {
  glm::vec2 offset{0.0f};
  float rotation = 0.0f;  // radians
  glm::vec2 scale{1.0f};
  bool present = false;   // the extension was given (an identity one included)
  glm::vec2 apply(glm::vec2 uv) const;
  // The same as a 3×3 matrix on (u, v, 1), column-major as GLSL's mat3 (the viewer's uniform).
  glm::mat3 matrix() const;
  // |det|: how the transform scales UV areas (texel footprints).
  float areaScale() const { return std::abs(scale.x * scale.y); }
};

struct Material {
  std::string name;
  glm::vec4 baseColorFactor{1.0f};  // linear
  int baseColorTexture = -1;        // index into Scene::textures, -1 none
  int baseColorTexCoord = 0;        // which TEXCOORD set the texture reads (KHR_texture_transform's texCoord wins)
  UvTransform baseColorUvTransform;  // KHR_texture_transform on baseColorTexture
  glm::vec3 emissiveFactor{0.0f};
  float emissiveStrength = 1.0f;    // KHR_materials_emissive_strength
  int emissiveTexture = -1;
  int emissiveTexCoord = 0;
  UvTransform emissiveUvTransform;   // KHR_texture_transform on emissiveTexture
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  float transmission = 0.0f;        // KHR_materials_transmission transmissionFactor (texture not read)
  bool doubleSided = false;
  int gltfMaterial = -1;            // source index, -1 for the default material
  std::string group;                // extras.irbake.group: the light group its emission is baked in ("": none named)
  int lightmapTexture = -1;         // MOZ_lightmap texture (index into Scene::textures), -1 none
  float lightmapIntensity = 1.0f;   // MOZ_lightmap intensity: map value = PNG value × intensity
  int lightmapTexCoord = 1;         // MOZ_lightmap texCoord as written (irview reads only TEXCOORD_1 and refuses others)
  // Read only with LoadOptions::shadingMaps (the viewer shades with them; a bake never reads them):
  int normalTexture = -1;           // normalTexture (index into Scene::textures, linear), -1 none
  int normalTexCoord = 0;           // which TEXCOORD set it reads
  float normalScale = 1.0f;         // normalTexture.scale: tangent-space x and y are multiplied by it
  // IRBAKE_lightmap_directional (docs/export.md): the L1x/L1y/L1z PNGs (indices into Scene::textures, linear,
  // value = (2·texel − 1)·scale), -1 none; and the float EXR pages, resolved beside the glTF ("" none).
  std::array<int, 3> directionalTextures{-1, -1, -1};
  std::array<float, 3> directionalScales{1.0f, 1.0f, 1.0f};
  std::array<std::string, 3> directionalExrPaths;
  // IRBAKE_shadowmask (docs/export.md): the RGBA mask page (index into Scene::textures, linear), -1 none.
  int shadowMaskTexture = -1;
  bool hasDirectionalTextures() const {
    return directionalTextures[0] >= 0 && directionalTextures[1] >= 0 && directionalTextures[2] >= 0;
  }
  // Emitted radiance scale (W/(m² sr)) before the emissive texture: factor × strength.
  glm::vec3 emission() const { return emissiveFactor * emissiveStrength; }
  // Light passes through (docs/units.md, "See-through surfaces"): BLEND (fraction 1 − α) or transmission.
  bool isTransmissive() const { return alphaMode == AlphaMode::Blend || transmission > 0.0f; }
  bool isEmissive() const { return glm::max(emissiveFactor.x, glm::max(emissiveFactor.y, emissiveFactor.z)) * emissiveStrength > 0.0f; }
};

// Where a lightmapped primitive's texels live (set by the atlas).
struct LightmapRef {
  int page = -1;               // -1: not lightmapped
  int width = 0, height = 0;   // page size in texels
};

// How an object takes part in the bake (extras.irbake.mode on its node, an ancestor node or its mesh; docs/guide.md
// "Per-object settings"). Baked: casts, bounces and gets map texels. ShadowOnly: casts and bounces, no texels.
// Probes: as ShadowOnly, and the clients light it from the irradiance probes. Off: not in the bake at all (the
// pipeline takes it out of the scene it bakes and hands it back to the export unchanged).
enum class ObjectMode { Baked, ShadowOnly, Probes, Off };
const char* toString(ObjectMode mode);
// "baked", "shadow-only", "probes" or "off"; false for anything else.
bool parseObjectMode(const std::string& text, ObjectMode& mode);

// One glTF primitive instanced by one node, flattened to world space.
// Vertex i is accessor vertex i of the source primitive (strips and fans are triangulated in indices),
// or sourceVertex[i] where vertices were split (flat normals for a primitive without NORMAL; atlas seams).
struct Primitive {
  std::string name;
  std::vector<glm::vec3> positions;  // world space, metres
  std::vector<glm::vec3> normals;    // world space, unit length (flat, as glTF requires, when absent)
  bool normalsComputed = false;      // the loader made them (NORMAL absent): their breaks are not authored seams
  std::vector<glm::vec2> uv0;        // TEXCOORD_0 (empty when absent)
  std::vector<glm::vec2> uv1;        // TEXCOORD_1: lightmap UV in [0,1] over the page (empty when absent)
  // TANGENT, world space: xyz unit, w = ±1 the bitangent's sign (glTF: bitangent = cross(normal, xyz) · w);
  // read only with LoadOptions::shadingMaps, empty when absent.
  std::vector<glm::vec4> tangents;
  std::vector<uint32_t> indices;     // triangle list, counter-clockwise front faces in world space
  int material = 0;                  // index into Scene::materials (always valid: a default is added)
  int node = -1, gltfMesh = -1, gltfPrimitive = -1;  // provenance for export
  // EXT_mesh_gpu_instancing: the instance of the node this primitive is (-1: the node itself, no
  // instancing), and that instance's transform, applied before the node's world matrix.
  int instance = -1;
  glm::mat4 instanceToNode{1.0f};
  glm::mat4 nodeToWorld{1.0f};       // the node's world matrix (positions here are already transformed)
  // Vertex i came from source accessor vertex sourceVertex[i] (empty: identity); set by the loader's
  // flat normals and by the atlas.
  std::vector<uint32_t> sourceVertex;
  LightmapRef lightmap;
  float lightmapScale = 1.0f;  // texel density multiplier (extras.irbake.lightmapScale on the node or mesh)
  ObjectMode mode = ObjectMode::Baked;  // extras.irbake.mode on the node (nearest ancestor) or the mesh
  bool getsLightmap() const { return mode == ObjectMode::Baked; }
  size_t triangleCount() const { return indices.size() / 3; }
};

// Ies: an EXT_lights_ies light, a point light whose intensity follows an IES LM-63 profile.
enum class LightType { Point, Spot, Directional, Ies };

// How a punctual light reaches the light map (mixed lighting): baked: its direct light and its bounces;
// indirect: its bounces only (the runtime shades its direct light); shadowmask: as indirect, plus its baked
// visibility in one channel of the shadow-mask pages (stages/shadow_mask).
enum class LightMode { Baked, Indirect, ShadowMask };
const char* toString(LightMode mode);
// "baked", "indirect" or "shadowmask"; false for anything else.
bool parseLightMode(const std::string& text, LightMode& mode);

// KHR_lights_punctual. intensity is radiant intensity (W/sr) for point/spot, irradiance (W/m²) for
// directional, so a point light gives E = I cosθ / r² and a directional light E = I cosθ. What a light of a
// type emits, gives and looks like in real time is its kind's (lights/light_kind.h).
struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;                  // 0: infinite
  float innerConeAngle = 0.0f;         // radians (spot)
  float outerConeAngle = 0.785398163f; // radians (spot), glTF default π/4
  glm::vec3 position{0.0f};            // world (point/spot)
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // world, unit, direction light travels (spot/directional)
  int node = -1;                       // -1 for lights from the command line
  int gltfLight = -1;                  // index in KHR_lights_punctual's lights (-1: from the command line)
  // Ies: the profile (candela), scaled by intensity (EXT_lights_ies' multiplier) × color; direction is its
  // nadir (θ = 0, the node's −Z) and profileAxisX its horizontal angle 0 (the node's +X), both world and unit.
  std::shared_ptr<const IesProfile> profile;
  glm::vec3 profileAxisX{1.0f, 0.0f, 0.0f};
  bool hasExtrasMode = false;          // the glTF light's extras.irbake.mode was given (then extrasMode holds it)
  LightMode extrasMode = LightMode::Baked;
  std::string group;                   // the glTF light's extras.irbake.group: its light group ("": none named)
  // What multiplies the inverse square law at a distance from the light: glTF's range (KHR_lights_punctual) as
  // the smooth window three.js and Babylon apply, clamp(1 − (d/range)⁴, 0, 1)², so the light fades to zero at
  // the range with no step, and is zero beyond it. 1 without a range (range 0).
  float rangeWindow(float distance) const {
    if (!(range > 0.0f)) return 1.0f;
    const float q = distance / range, q2 = q * q;
    const float w = 1.0f - q2 * q2;  // at most 1
    return w > 0.0f ? w * w : 0.0f;
  }
  // The bake's cut of a light without range (lights/light_reach.h): 0 (no cut), or the distance where its light
  // ends, faded out by a smoothstep over the last quarter so the cut draws no ring.
  float cutoff = 0.0f;
  float cutoffWindow(float distance) const {
    if (!(cutoff > 0.0f) || distance <= 0.75f * cutoff) return 1.0f;
    if (distance >= cutoff) return 0.0f;
    const float t = (distance - 0.75f * cutoff) / (0.25f * cutoff);
    return 1.0f - t * t * (3.0f - 2.0f * t);
  }
};

struct Camera {
  std::string name;
  glm::mat4 cameraToWorld{1.0f};  // looks down -Z, +Y up (glTF)
  float yfov = 0.8f;              // radians
  float aspectRatio = 0.0f;       // 0: from the viewport
  float znear = 0.01f, zfar = 0.0f;  // zfar 0: infinite
  int node = -1;
};

struct LoadStats {
  size_t trianglesKept = 0;
  size_t trianglesDropped = 0;     // degenerate: zero area or repeated indices
  size_t primitivesSkipped = 0;    // points/lines
  size_t normalsComputed = 0;      // primitives whose normals were computed
  size_t gpuInstancedNodes = 0;    // nodes with EXT_mesh_gpu_instancing
  size_t gpuInstances = 0;         // their instances, each a mesh instance of its own
  // Compression extensions the file used and the loaded document no longer does (scene/gltf_decompress.h).
  std::vector<std::string> decodedExtensions;
  std::vector<std::string> warnings;
};

// What a see-through surface lets pass at a point: `fraction` of the light goes straight through, tinted by
// the base colour (transmittance fraction × tint); the rest meets a Lambertian surface of that colour.
struct SurfaceTransmission {
  float fraction = 0.0f;
  glm::vec3 tint{1.0f};
  glm::vec3 transmittance() const { return tint * fraction; }
};

// A light an irbake export leaves to the client (docs/export.md "Mixed lights"): its direct light is not in
// the map, the client shades it, times channel `maskChannel` of the material's shadow mask (-1: unshadowed).
struct RuntimeLight {
  Light light;
  LightMode mode = LightMode::Indirect;
  int maskChannel = -1;  // 0..3 (R, G, B, A) for a shadowmask light
};

struct Scene {
  std::string sourcePath;          // the glTF it came from ("" for generated scenes)
  std::vector<Primitive> primitives;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  std::vector<Camera> cameras;
  Environment environment;         // the sky (none unless --sky / --env)
  LoadStats stats;
  // Baked float pages named in the root extras of an irbake export ("lightmapPages": [uri, ...]),
  // resolved to paths beside the glTF; empty for other scenes.
  std::vector<std::string> lightmapExrPaths;
  // An export's mixed lights (read only with LoadOptions::shadingMaps, scene/runtime_lights.h).
  std::vector<RuntimeLight> runtimeLights;

  Bounds3 bounds() const;
  size_t triangleCount() const;
  // Total emitted power of emissive surfaces (W, RGB): π · Le · area, emissive texture averaged per triangle.
  glm::vec3 emitterPower() const;
  bool hasEmissiveSurface() const;  // any primitive whose material emits
  bool hasLightOrEmitter() const;
  // Base colour (linear RGBA) at a point of a triangle: factor × texture(bilinear, wrap) at its UV.
  glm::vec4 baseColorAt(const Primitive& prim, uint32_t triangle, glm::vec2 barycentric) const;
  // The see-through part of a surface at a point (fraction 0 for opaque and MASK materials).
  SurfaceTransmission transmissionAt(const Primitive& prim, uint32_t triangle, glm::vec2 barycentric) const;
  // Emitted radiance (W/(m² sr)) at a point of a triangle: emissiveFactor × strength × texture.
  glm::vec3 emissionAt(const Primitive& prim, uint32_t triangle, glm::vec2 barycentric) const;
};

// Bilinear texture lookup with the texture's wrap modes; uv as in glTF (v down).
glm::vec4 sampleBilinear(const Texture& tex, glm::vec2 uv);

}  // namespace irbake
