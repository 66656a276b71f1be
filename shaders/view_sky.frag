// irview's sky: the environment map behind the scene. Each pixel reads the texel the baker's
// Environment::radiance reads for the pixel's view direction (scene/environment.h: +Y up, θ = π v from +Y,
// φ = 2π u − π, d = (sinθ sinφ, cosθ, −sinθ cosφ), `rotation` about +Y), nearest, so a screenshot holds the
// map's radiance exactly. OUTPUT as view_mesh.frag: 0 linear radiance, 1 exposure + sRGB encode.
#ifndef OUTPUT
#define OUTPUT 0
#endif
uniform mat4 uInverseViewProjection;
uniform vec2 uViewportSize;      // pixels
uniform sampler2D uEnvironment;  // RGB32F, row 0 = the image's top row
uniform float uRotation;         // radians about +Y
uniform float uExposureScale;    // 2^EV (OUTPUT 1)

out vec4 fragColor;

void main() {
  vec2 ndc = gl_FragCoord.xy / uViewportSize * 2.0 - 1.0;
  vec4 nearPoint = uInverseViewProjection * vec4(ndc, -1.0, 1.0);
  vec4 farPoint = uInverseViewProjection * vec4(ndc, 0.0, 1.0);  // any point further along the ray
  vec3 d = normalize(farPoint.xyz / farPoint.w - nearPoint.xyz / nearPoint.w);
  // Into the map's frame: undo the rotation about +Y.
  float c = cos(uRotation), s = sin(uRotation);
  vec3 m = vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
  const float pi = 3.14159265358979;
  float theta = acos(clamp(m.y, -1.0, 1.0));
  float phi = atan(m.x, -m.z);
  ivec2 size = textureSize(uEnvironment, 0);
  ivec2 texel = clamp(ivec2(int((phi + pi) / (2.0 * pi) * float(size.x)), int(theta / pi * float(size.y))),
                      ivec2(0), size - 1);
  vec3 color = texelFetch(uEnvironment, texel, 0).rgb;
#if OUTPUT == 1
  color = encodeSrgb(color * uExposureScale);
#endif
  fragColor = vec4(color, 1.0);
}
