// The optional sun level of IRBAKE_light_probes (docs/export.md, `sun`; baker/lightmap/probe_grid.h,
// ProbeSunLevel): the strongest directional light's visibility on a lattice S times finer than the grid, as bits,
// in the cells its shadow crosses. A point p of such a cell takes its probes' blend plus
// (v_fine(p) − Σ w_i v_i) · sh: v_fine the trilinear interpolation of the cell's (S+1)³ bits, v_i the visibility
// probe i's coefficients carry, w_i the blend's own (renormalised) weights. The clients shade the sun itself as an
// exact clamped cosine, v(p)·irradiance·max(0, n·(−direction)), and the rest of the light (c − v·sh) through L2.
import { Vector3, Vector4 } from 'three';

const FLOAT = 5126, UNSIGNED_INT = 5125;
const MAX_SUBDIVISIONS = 16;
const FIELD = 'IRBAKE_light_probes.sun';

function fail(field, message) { throw new Error(`${FIELD}.${field}: ${message}`); }

export class IrbakeSunLevel {
  constructor({ direction, irradiance, sh, visibility, cells, subdivisions, fine }) {
    Object.assign(this, { direction, irradiance, sh, visibility, cells, subdivisions, fine });
    this.wordsPerCell = Math.ceil((subdivisions + 1) ** 3 / 32);
  }

  // v_fine at the cell-local fraction t ([0, 1]³) of the cell whose base probe is `base`; -1 when it is not refined.
  fineVisibility(base, t) {
    let lo = 0, hi = this.cells.length;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (this.cells[mid] < base) lo = mid + 1; else hi = mid; }
    if (lo === this.cells.length || this.cells[lo] !== base) return -1;
    const S = this.subdivisions, s1 = S + 1, words = lo * this.wordsPerCell;
    const i0 = [0, 0, 0], f = [0, 0, 0];
    for (let a = 0; a < 3; ++a) {
      const x = Math.min(Math.max(t[a], 0), 1) * S;
      i0[a] = Math.min(Math.floor(x), S - 1);
      f[a] = x - i0[a];
    }
    let v = 0;
    for (let k = 0; k < 8; ++k) {
      const d = [k & 1, (k >> 1) & 1, (k >> 2) & 1];
      let w = 1;
      for (let a = 0; a < 3; ++a) w *= d[a] ? f[a] : 1 - f[a];
      const n = i0[0] + d[0] + s1 * (i0[1] + d[1] + s1 * (i0[2] + d[2]));
      if (w > 0 && (this.fine[words + (n >> 5)] >>> (n & 31)) & 1) v += w;
    }
    return v;
  }
}

// The `sun` object of the extension `ext` for a grid of `counts` (n probes), its accessors read by
// `read(field, componentType, type, count)` (checked types and counts, values as an array). Throws an Error
// naming the field, as irbake's reader does.
export async function readSunLevel(ext, counts, read) {
  const sun = ext.sun;
  if (!sun || typeof sun !== 'object' || Array.isArray(sun)) throw new Error(`${FIELD}: not an object`);
  const S = sun.subdivisions;
  if (!Number.isInteger(S) || S < 1 || S > MAX_SUBDIVISIONS) fail('subdivisions', `needs a whole number from 1 to ${MAX_SUBDIVISIONS}`);
  const direction = sun.direction;
  if (!Array.isArray(direction) || direction.length !== 3 || !direction.every(x => typeof x === 'number')) fail('direction', 'needs 3 numbers');
  if (!direction.every(Number.isFinite)) fail('direction', 'not finite');
  if (Math.abs(Math.hypot(...direction) - 1) > 1e-3) fail('direction', 'not a unit vector');
  const irradiance = sun.irradiance;
  if (!Array.isArray(irradiance) || irradiance.length !== 3 || !irradiance.every(x => typeof x === 'number')) fail('irradiance', 'needs 3 numbers');
  if (!irradiance.every(Number.isFinite)) fail('irradiance', 'not finite');
  if (irradiance.some(x => x < 0)) fail('irradiance', 'negative');
  const n = counts[0] * counts[1] * counts[2];
  const sh = await read('sh', FLOAT, 'VEC3', 9);
  if (!sh.every(Number.isFinite)) fail('sh', 'a non-finite coefficient');
  const packed = await read('visibility', UNSIGNED_INT, 'SCALAR', Math.ceil(n / 4));  // a byte each, k/255
  const visibility = new Float32Array(n);
  for (let i = 0; i < n; ++i) visibility[i] = ((packed[i >> 2] >>> (8 * (i & 3))) & 255) / 255;
  // `cells` and `fine` are omitted together when no cell is refined.
  const refined = sun.cells !== undefined || sun.fine !== undefined;
  const cells = refined ? await read('cells', UNSIGNED_INT, 'SCALAR', null) : new Uint32Array(0);
  const [nx, ny] = counts;
  for (let c = 0; c < cells.length; ++c) {
    const i = cells[c], ijk = [i % nx, Math.floor(i / nx) % ny, Math.floor(i / (nx * ny))];
    if (!(i < n) || ijk.some((v, a) => v >= Math.max(1, counts[a] - 1))) fail('cells', `${i} is not a cell of the grid`);
    if (c > 0 && i <= cells[c - 1]) fail('cells', `not in ascending order at element ${c}`);
  }
  const fine = refined ? await read('fine', UNSIGNED_INT, 'SCALAR', cells.length * Math.ceil((S + 1) ** 3 / 32)) : new Uint32Array(0);
  return new IrbakeSunLevel({ direction, irradiance, sh, visibility, cells, subdivisions: S, fine });
}

// The sun's shader uniforms for a material lit by the probes: the level `sun` (null: none, all zero), the
// visibility at the object's centre and its gradient (irbake_light_probes.js, field).
export function sunUniforms(sun, visibility, gradient) {
  const sh = [...Array(9)].map((_, k) => (sun ? new Vector3(sun.sh[3 * k], sun.sh[3 * k + 1], sun.sh[3 * k + 2]) : new Vector3()));
  return {
    irbakeSunSh: { value: sh },
    irbakeSunIrradiance: { value: new Vector3(...(sun ? sun.irradiance : [0, 0, 0])) },
    irbakeSunDirection: { value: new Vector3(...(sun ? sun.direction : [0, -1, 0])) },
    irbakeSunVisibility: { value: new Vector4(...gradient, sun ? visibility : 0) },  // xyz: gradient, w: at the centre
  };
}

// GLSL for those uniforms: `visibility` sets irbakeSunV at the fragment (irbakeProbeOffset from the centre), the
// sun's SH is taken out of the probes' at it, `direct` is the sun's exact E/π at the world normal irbakeN.
export const SUN_SHADER = {
  uniforms: 'uniform vec3 irbakeSunSh[ 9 ];\nuniform vec3 irbakeSunIrradiance;\nuniform vec3 irbakeSunDirection;\nuniform vec4 irbakeSunVisibility;',
  visibility: 'float irbakeSunV = clamp( irbakeSunVisibility.w + dot( irbakeProbeOffset, irbakeSunVisibility.xyz ), 0.0, 1.0 );',
  direct: 'irbakeSunV * irbakeSunIrradiance * max( 0.0, - dot( irbakeN, irbakeSunDirection ) )',
};
