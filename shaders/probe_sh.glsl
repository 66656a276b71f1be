// Irradiance/π of L2 SH coefficients at unit normal n, as three.js's SphericalHarmonics3.getIrradianceAt
// (lightmap/probe_grid.h, shIrradiance). Concatenated before view_probe.frag and view_mesh.frag.
vec3 shIrradiance(vec3 sh[9], vec3 n) {
  float x = n.x, y = n.y, z = n.z;
  vec3 r = sh[0] * 0.886227;
  r += sh[1] * (2.0 * 0.511664 * y) + sh[2] * (2.0 * 0.511664 * z) + sh[3] * (2.0 * 0.511664 * x);
  r += sh[4] * (2.0 * 0.429043 * x * y) + sh[5] * (2.0 * 0.429043 * y * z);
  r += sh[6] * (0.743125 * z * z - 0.247708) + sh[7] * (2.0 * 0.429043 * x * z);
  r += sh[8] * (0.429043 * (x * x - y * y));
  return r;
}
