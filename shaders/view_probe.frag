// irview's probe spheres: the ray from the eye through this fragment meets the sphere at p, normal
// n = (p − centre)/r; a white Lambert surface there shows E(n)/π, the probes' SH at p (the centre's plus
// (p − centre)·gradient, lightmap/probe_field.h) convolved with the clamped cosine as three.js's
// shGetIrradianceAt writes it (lightmap/probe_grid.h, shIrradiance), clamped at 0, plus the exact emitters' E/π
// (probe_emitters.glsl). With a sun level its sun is taken out of the SH at the visibility v(p) and added as an
// exact clamped cosine (shadeProbeLambert).
uniform mat4 uViewProjection;
uniform vec3 uEye;
uniform vec3 uCentre;
uniform float uRadius;
uniform vec3 uSh[9];
uniform vec3 uShGradient[27];  // ∂uSh/∂x (0..8), ∂uSh/∂y (9..17), ∂uSh/∂z (18..26)
uniform int uValid;
uniform vec3 uSunDirection;   // the sun level's travel direction
uniform vec3 uSunIrradiance;  // E/π facing it at visibility 1 (0: no sun level)
uniform vec3 uSunSh[9];       // its SH at visibility 1
uniform float uSunVisibility; // v at the centre, and its gradient
uniform vec3 uSunGradient;
uniform float uExposureScale;
in vec3 vWorld;
out vec4 fragColor;

void main() {
  vec3 d = normalize(vWorld - uEye);
  vec3 oc = uEye - uCentre;
  float b = dot(oc, d);
  vec3 closest = oc - b * d;  // centre → the ray's closest point: h below without b² − c's cancellation
  float h = uRadius * uRadius - dot(closest, closest);
  if (h < 0.0) discard;
  float t = -b - sqrt(h);
  if (t < 0.0) discard;  // the eye is inside the sphere or past it
  vec3 p = uEye + t * d;
  vec3 n = normalize(p - uCentre);
  vec4 clip = uViewProjection * vec4(p, 1.0);
  gl_FragDepth = clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);
  vec3 o = p - uCentre, sh[9];
  float v = clamp(uSunVisibility + dot(o, uSunGradient), 0.0, 1.0);
  for (int k = 0; k < 9; ++k)
    sh[k] = uSh[k] + o.x * uShGradient[k] + o.y * uShGradient[9 + k] + o.z * uShGradient[18 + k] - v * uSunSh[k];
  vec3 radiance = max(shIrradiance(sh, n), vec3(0.0)) + v * uSunIrradiance * max(0.0, -dot(n, uSunDirection));
#if EMITTER_TRIANGLES > 0
  radiance += exactEmitterLight(p, n, o);
#endif
  if (uValid == 0) radiance = vec3(1.0, 0.0, 0.0);
#if OUTPUT == 1
  fragColor = vec4(encodeSrgb(radiance * uExposureScale), 1.0);
#else
  fragColor = vec4(radiance, 1.0);
#endif
}
