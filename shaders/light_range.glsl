// glTF's range (KHR_lights_punctual) on the inverse square law, a line-by-line port of Light::rangeWindow
// (baker/scene/scene.h): clamp(1 − (d/range)⁴, 0, 1)², zero at and beyond the range; 1 without one (range 0).
// Concatenated before the bake's direct-light shader and irview's mixed lights.
float rangeWindow(float distance, float range) {
  if (!(range > 0.0)) return 1.0;
  float q = distance / range, q2 = q * q;
  float w = 1.0 - q2 * q2;  // at most 1
  return w > 0.0 ? w * w : 0.0;
}
