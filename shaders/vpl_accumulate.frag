// Accumulation: every texel sample of a page against a batch of VPLs, each with its depth cube
// (layers 6k..6k+5 of a 2D array: a cube in the VPL's normal-aligned frame, reversed-Z: depth = near / axis distance).
// Output: the batch's contribution to irradiance/π, summed by additive blending.
layout(binding = 0) uniform sampler2DArray gPositionWeight;  // xyz world position, w coverage weight
layout(binding = 1) uniform sampler2DArray gNormal;          // xyz unit shading normal
layout(binding = 2) uniform sampler2DArray vplDepth;     // 6 layers per VPL cube

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
  float noClamp = clampBound > 0.0 ? clampBound : 3.0e38;
  for (int l = 0; l < layers; ++l) {
    vec4 pw = texelFetch(gPositionWeight, ivec3(p, l), 0);
    if (pw.w <= 0.0) continue;
    vec3 nx = texelFetch(gNormal, ivec3(p, l), 0).xyz;
    vec3 s = vec3(0.0);
    for (int k = 0; k < vplCount; ++k) {
      vec3 ny = vpls[k].normal.xyz;
      vec3 d = vpls[k].origin.xyz - pw.xyz;  // receiver → VPL
      float cx = dot(nx, d), cy = -dot(ny, d);
      if (cx <= 0.0 || cy <= 0.0) continue;
      float r2 = dot(d, d);
      float g = min(cx * cy / (r2 * r2), noClamp);  // vplGeometryTerm, inlined
      float r = sqrt(r2);
      float footprint = r * texelAngle;
      // Lookup point: pushed along the receiver normal, relative to the shadow origin (VPL + offset·ny).
      vec3 q = nx * (normalOffset * footprint) - d - ny * vpls[k].origin.w;
      vec3 local = vec3(dot(q, vpls[k].tangent.xyz), dot(q, vpls[k].bitangent.xyz), dot(q, ny));
      float bias = shadowBiasTan(constantBias, slopeBias, footprint, sqrt(max(r2 - cx * cx, 0.0)) / cx);
#ifdef SHADOW_PCF
      s += vpls[k].power.rgb * (g * cubeVisibilityPcf(vplDepth, k, local, nearPlane, bias));
#else
      float axisDistance;
      float depth = cubeDepth(vplDepth, k, local, axisDistance);
      if (cubeLit(depth, axisDistance, nearPlane, bias)) s += vpls[k].power.rgb * g;
#endif
    }
    sum += pw.w * s;
  }
  result = vec4(sum * kInvPi2, 0.0);
}
