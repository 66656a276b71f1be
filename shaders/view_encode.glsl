// irview's display encode, shared by view_mesh.frag and view_sky.frag (concatenated before them).
// The sRGB encode (IEC 61966-2-1) without pow(): above the linear toe, 1.055 c^(1/2.4) − 0.055 is
// fitted (minimax over [0.0031308, 1]) by a·c^(1/2) + b·c^(1/4) + d·c + e. Max error 3.6e-4, a tenth
// of an 8-bit step; llvmpipe's pow() is a log2 and an exp2 polynomial each, this is two sqrt and
// three multiply-adds.
vec3 encodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  vec3 s1 = sqrt(c), s2 = sqrt(s1);
  vec3 curve = 0.83380291 * s1 + 0.298077591 * s2 - 0.0553457088 * c - 0.0768988119;
  return mix(c * 12.92, curve, step(vec3(0.0031308), c));
}
