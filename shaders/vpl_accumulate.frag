// Accumulation: every texel sample of a page against a batch of VPLs, each with its depth cube
// (cube-map array layer k, cube in the VPL's normal-aligned frame, reversed-Z: depth = near / axis distance).
// Output: the batch's contribution to irradiance/π, summed by additive blending.
layout(binding = 0) uniform sampler2DArray gPositionWeight;  // xyz world position, w coverage weight
layout(binding = 1) uniform sampler2DArray gNormal;          // xyz unit shading normal
layout(binding = 2) uniform samplerCubeArray vplDepth;

struct VplGpu {
  vec4 origin;     // xyz: shadow origin (VPL offset along its normal)
  vec4 normal;     // xyz: unit normal = local +Z
  vec4 power;      // rgb: Φ (W)
  vec4 tangent;    // xyz: local +X
  vec4 bitangent;  // xyz: local +Y
};
layout(std140, binding = 0) uniform VplBatch { VplGpu vpls[MAX_BATCH]; };

uniform int vplCount;
uniform int layers;            // S×S supersample layers
uniform float clampBound;      // geometry-term clamp (1/m²), ≤ 0: none
uniform float nearPlane;       // cube near plane (m)
uniform float constantBias;    // m
uniform float slopeBias;       // in shadow texels
uniform float normalOffset;    // in shadow texels
uniform float texelAngle;      // angular size of one cube texel at the face centre (2 / faceSize)

layout(location = 0) out vec4 result;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 sum = vec3(0.0);
  for (int l = 0; l < layers; ++l) {
    vec4 pw = texelFetch(gPositionWeight, ivec3(p, l), 0);
    if (pw.w <= 0.0) continue;
    vec3 nx = texelFetch(gNormal, ivec3(p, l), 0).xyz;
    vec3 s = vec3(0.0);
    for (int k = 0; k < vplCount; ++k) {
      vec3 o = vpls[k].origin.xyz;
      vec3 ny = vpls[k].normal.xyz;
      vec3 d = o - pw.xyz;
      float g = vplGeometryTerm(d, nx, ny, clampBound);
      if (g <= 0.0) continue;
      float r = length(d);
      float footprint = r * texelAngle;
      vec3 q = pw.xyz + nx * (normalOffset * footprint) - o;
      vec3 local = vec3(dot(q, vpls[k].tangent.xyz), dot(q, vpls[k].bitangent.xyz), dot(q, ny));
      float depth = texture(vplDepth, vec4(local, float(k))).r;
      float occluder = depth > 0.0 ? nearPlane / depth : 1e30;
      float bias = shadowBias(constantBias, slopeBias, footprint, dot(nx, d) / r);
      if (cubeAxisDistance(local) > occluder + bias) continue;
      s += vpls[k].power.rgb * g;
    }
    sum += pw.w * s;
  }
  result = vec4(sum * kInvPi2, 0.0);
}
