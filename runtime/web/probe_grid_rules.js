// Where irview accepts an IRBAKE_light_probes grid (docs/refusals.md), with irview's messages, for the three.js
// plugin (irbake_light_probes.js) and the glTF-Transform extension (gltf_transform_irbake.mjs): the place a bake
// can write, as irbake's reader checks it (baker/export/light_probes_export.cpp, checkGridPlace and the offsets).
// Beyond it irview's visibility rays would start where Embree aborts, and a spacing of 1e-30 puts every point
// outside the grid, so a client that showed such a grid would show what irview refuses.
export const LIGHT_PROBES = 'IRBAKE_light_probes';
export const MIN_PROBE_SPACING = Math.fround(0.01);  // kMinProbeSpacing, a 32-bit float as irview compares it
export const MAX_SCENE_COORDINATE = 1e9;             // kMaxSceneCoordinate, metres
const SCENE_LIMIT_SLACK = 1e-6;                      // kSceneLimitSlack: the limit itself, rounded to float, is inside

// x as C's printf("%.3g") writes it, irview's short notation for lengths ("3e+38", "0.005"): 3 significant
// digits rounded half to even on x's exact binary value, trailing zeros dropped, exponent style below 1e-4 or
// from 1e3 with at least two exponent digits. Exact (BigInt) because JavaScript's toPrecision rounds a tie such
// as 0.3125 up where printf gives "0.312".
export function shortLength(x) {
  if (Number.isNaN(x)) return 'nan';
  if (!Number.isFinite(x)) return x < 0 ? '-inf' : 'inf';
  const sign = x < 0 || Object.is(x, -0) ? '-' : '';
  x = Math.abs(x);
  if (x === 0) return `${sign}0`;
  // x = mantissa × 2^exponent exactly, as the fraction num / den.
  const bits = new DataView(new ArrayBuffer(8));
  bits.setFloat64(0, x);
  const high = bits.getUint32(0), low = bits.getUint32(4);
  const biased = (high >>> 20) & 0x7ff;
  let mantissa = (BigInt(high & 0xfffff) << 32n) | BigInt(low);
  if (biased > 0) mantissa |= 1n << 52n;
  const exponent = (biased > 0 ? biased : 1) - 1075;
  let num = mantissa, den = 1n;
  if (exponent >= 0) num <<= BigInt(exponent);
  else den <<= BigInt(-exponent);
  const digits = 3;
  // The decimal exponent e with 10^e ≤ x < 10^(e+1); the estimate is off by at most one.
  let e = Math.floor(Math.log10(x));
  const atLeast = k => (k >= 0 ? num >= den * 10n ** BigInt(k) : num * 10n ** BigInt(-k) >= den);
  if (!atLeast(e)) --e;
  else if (atLeast(e + 1)) ++e;
  // The significand: x × 10^(digits − 1 − e), rounded half to even.
  const shift = digits - 1 - e;
  const n = shift >= 0 ? num * 10n ** BigInt(shift) : num, d = shift >= 0 ? den : den * 10n ** BigInt(-shift);
  let q = n / d;
  const twice = 2n * (n % d);
  if (twice > d || (twice === d && q % 2n === 1n)) ++q;
  if (q === 10n ** BigInt(digits)) { q /= 10n; ++e; }
  const text = q.toString();
  if (e < -4 || e >= digits) {
    const fraction = text.slice(1).replace(/0+$/, '');
    const lead = `${text[0]}${fraction ? `.${fraction}` : ''}`;
    return `${sign}${lead}e${e < 0 ? '-' : '+'}${String(Math.abs(e)).padStart(2, '0')}`;
  }
  const point = e + 1;  // digits before the decimal point
  const whole = point <= 0 ? '0' : text.slice(0, point);
  const fraction = (point <= 0 ? `${'0'.repeat(-point)}${text}` : text.slice(point)).replace(/0+$/, '');
  return `${sign}${whole}${fraction ? `.${fraction}` : ''}`;
}

// Throws an Error naming the field when the grid of `origin` and `spacing` (32-bit floats, as irview reads them)
// and `counts` (whole numbers ≥ 1) lies where no bake writes one: a spacing outside 0.01 … 1e9 m, an origin
// coordinate or a far corner (origin + spacing × (counts − 1)) beyond 1e9 m. Axis by axis, origin before far
// corner, as irview reports the first it meets.
export function checkProbeGridPlace(origin, spacing, counts) {
  if (!(spacing >= MIN_PROBE_SPACING) || !(spacing <= MAX_SCENE_COORDINATE))
    throw new Error(`${LIGHT_PROBES}.spacing: ${shortLength(spacing)} m is outside the 0.01 … 1e9 m a bake writes`);
  const limit = MAX_SCENE_COORDINATE * (1 + SCENE_LIMIT_SLACK);
  for (let a = 0; a < 3; ++a) {
    if (!(Math.abs(origin[a]) <= limit))
      throw new Error(`${LIGHT_PROBES}.origin: ${shortLength(origin[a])} m is beyond the supported 1e9 m`);
    const far = origin[a] + spacing * (counts[a] - 1);
    if (!(Math.abs(far) <= limit))
      throw new Error(`${LIGHT_PROBES}.counts: the grid reaches ${shortLength(far)} m, beyond the supported 1e9 m ` +
                      '(origin + spacing × (counts − 1))');
  }
}

// Throws an Error naming probe `index` when its offset (3 finite 32-bit floats at offsets[3 index]) moves it more
// than `spacing` from its grid point along any axis: a bake moves a probe at most half a spacing, out of a wall.
export function checkProbeOffset(offsets, index, spacing) {
  const away = Math.max(Math.abs(offsets[3 * index]), Math.abs(offsets[3 * index + 1]), Math.abs(offsets[3 * index + 2]));
  if (away > spacing)
    throw new Error(`${LIGHT_PROBES}.offsets: probe ${index} is moved ${shortLength(away)} m from its grid point, more ` +
                    'than a spacing (a bake moves it at most half)');
}
