// A GLTFLoader plugin for IRBAKE_light_probes (docs/export.md): irbake's grid of irradiance probes, read, checked
// and used to light dynamic meshes the way irview's --probe-object does (runtime/probe_view.h).
//   root.extensions.IRBAKE_light_probes = { origin, spacing, counts, coefficients, offsets, valid, ... }
// Probe (i, j, k), index i + nx (j + ny k), stands at origin + spacing (i, j, k); it holds 9 RGB coefficients of
// three.js's SphericalHarmonics3 of the incident radiance / π (E(n)/π = shGetIrradianceAt(n)), validity 0 or 1.
// lightObject(mesh) blends the 8 probes around the mesh's centre (trilinear, valid ones only, weights
// renormalised: baker/lightmap/probe_grid.h, interpolateProbes, without its visibility rays as irview) and their
// gradient over its bounding radius (the secant of the blends at centre ± r: baker/lightmap/probe_field.h), so a
// surface point p takes the SH c + (p − centre)·∇c; its Lambert material then adds radiance = albedo ×
// max(0, shGetIrradianceAt(n)): the same value as irview, since three.js shades irradiance × albedo/π and the
// material's probe term is π × E/π.
// With the optional `sun` level (irbake_probe_sun.js), a point in one of its cells takes the blend with its sun
// replaced by the finer lattice's, and the sun is shaded as an exact clamped cosine at its visibility v(p) (blended
// and given a gradient as the coefficients), taken out of the L2 term: max(0, shGetIrradianceAt(n, c − v·sh)) +
// v·irradiance·max(0, n·(−direction)), as irview and `irbake probe --normal` (probe_grid.h, shadeProbeLambert).
// With the optional `emitters` (irbake_probe_emitters.js), their exact light is added at each point, their
// visibility blended as the SH.
// A grid that does not fit (counts or spacing out of range, an accessor of the wrong type or count, a
// non-finite value, validity other than 0 or 1) or lies where no bake writes one (probe_grid_rules.js: a spacing
// outside 0.01 … 1e9 m, an origin or far corner beyond 1e9 m, a probe moved more than a spacing) is refused:
// loading throws an Error naming the field, with irview's message.
import { Box3, SphericalHarmonics3, Vector3, Vector4 } from 'three';
import { checkProbeGridPlace, checkProbeOffset, LIGHT_PROBES } from './probe_grid_rules.js';
import { readSunLevel, SUN_SHADER, sunUniforms } from './irbake_probe_sun.js';
import { emitterGlsl, emitterUniforms, readEmitters, visibilityField } from './irbake_probe_emitters.js';

export { LIGHT_PROBES };
const FLOAT = 5126;
const COMPONENTS = { SCALAR: 1, VEC3: 3 };

// The probe grid: coefficients (Float32Array, 27 per probe: SphericalHarmonics3.fromArray's layout), offsets
// (3 per probe), valid (Uint8Array).
export class IrbakeProbeGrid {
  constructor({ origin, spacing, counts, coefficients, offsets, valid, sun = null, emitters = [] }) {
    Object.assign(this, { origin, spacing, counts, coefficients, offsets, valid, sun, emitters });
  }

  get size() { return this.counts[0] * this.counts[1] * this.counts[2]; }
  index(i, j, k) { return i + this.counts[0] * (j + this.counts[1] * k); }
  // Where probe `index` was baked: its grid point plus its offset.
  position(index) {
    const [nx, ny] = this.counts;
    const ijk = [index % nx, Math.floor(index / nx) % ny, Math.floor(index / (nx * ny))];
    return ijk.map((v, a) => this.origin[a] + this.spacing * v + this.offsets[3 * index + a]);
  }

  // The SH at point p ([x, y, z]): { coefficients: Float64Array(27), probes, weight, sunVisibility }. Trilinear
  // over the 8 probes around p (clamped to the grid), valid ones only; where none is valid, the nearest valid probe
  // of the 4×4×4 around p; probes 0 when there is none. In a cell of the sun level, the blend's sun is the
  // lattice's; sunVisibility is the visibility the coefficients carry (0 without a sun level).
  interpolate(p) {
    const out = { coefficients: new Float64Array(27), probes: 0, weight: 0, corners: [], sunVisibility: 0 };
    const base = [0, 0, 0], t = [0, 0, 0];
    let sunBlend = 0;
    for (let a = 0; a < 3; ++a) {
      const n = this.counts[a];
      const f = Math.fround((Math.fround(p[a]) - this.origin[a]) / this.spacing);
      const c = Math.min(Math.max(f, 0), n - 1);
      base[a] = Math.min(Math.floor(c), Math.max(0, n - 2));
      t[a] = n > 1 ? c - base[a] : 0;
    }
    for (let corner = 0; corner < 8; ++corner) {
      const d = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
      const q = d.map((v, a) => base[a] + v);
      if (q.some((v, a) => v > this.counts[a] - 1)) continue;  // a one-probe axis: its single layer counted once
      let w = 1;
      for (let a = 0; a < 3; ++a) w *= d[a] ? t[a] : 1 - t[a];
      const idx = this.index(q[0], q[1], q[2]);
      if (w <= 0 || !this.valid[idx]) continue;
      for (let k = 0; k < 27; ++k) out.coefficients[k] += w * this.coefficients[27 * idx + k];
      if (this.sun) sunBlend += w * this.sun.visibility[idx];
      out.weight += w;
      ++out.probes;
      out.corners.push([idx, w]);
    }
    if (out.weight > 0) {
      for (let k = 0; k < 27; ++k) out.coefficients[k] /= out.weight;
      for (const c of out.corners) c[1] /= out.weight;
      const fine = this.sun ? this.sun.fineVisibility(this.index(base[0], base[1], base[2]), t) : -1;
      if (fine >= 0)
        for (let k = 0; k < 27; ++k) out.coefficients[k] += (fine - sunBlend / out.weight) * this.sun.sh[k];
      if (this.sun) out.sunVisibility = fine >= 0 ? fine : sunBlend / out.weight;
      return out;
    }
    let best = Infinity, nearest = -1;
    for (let k = base[2] - 1; k <= base[2] + 2; ++k)
      for (let j = base[1] - 1; j <= base[1] + 2; ++j)
        for (let i = base[0] - 1; i <= base[0] + 2; ++i) {
          if (i < 0 || j < 0 || k < 0 || i >= this.counts[0] || j >= this.counts[1] || k >= this.counts[2]) continue;
          const idx = this.index(i, j, k);
          const q = this.position(idx);
          const d2 = (q[0] - p[0]) ** 2 + (q[1] - p[1]) ** 2 + (q[2] - p[2]) ** 2;
          if (d2 < best && this.valid[idx]) { best = d2; nearest = idx; }
        }
    if (nearest < 0) return out;
    out.coefficients.set(this.coefficients.subarray(27 * nearest, 27 * nearest + 27));
    out.probes = 1;
    out.weight = 1;
    if (this.sun) out.sunVisibility = this.sun.visibility[nearest];
    out.corners = [[nearest, 1]];
    return out;
  }

  // The probes over an object of bounding radius r around `centre`: the blend there ({ coefficients, probes,
  // weight, sunVisibility }) and gradient (3 Float64Array(27): per metre along x, y, z; sunGradient the same for
  // sunVisibility), the secant of the blends at centre ± r; an axis whose blend at either end finds no probe keeps a
  // zero gradient (probeFieldOver).
  field(centre, radius) {
    const blend = this.interpolate(centre);
    const gradient = [0, 1, 2].map(() => new Float64Array(27)), sunGradient = [0, 0, 0];
    if (blend.probes === 0 || !(radius > 0)) return { ...blend, gradient, sunGradient };
    for (let a = 0; a < 3; ++a) {
      const hi = this.interpolate(centre.map((v, i) => (i === a ? v + radius : v)));
      const lo = this.interpolate(centre.map((v, i) => (i === a ? v - radius : v)));
      if (hi.probes === 0 || lo.probes === 0) continue;
      for (let k = 0; k < 27; ++k) gradient[a][k] = (hi.coefficients[k] - lo.coefficients[k]) / (2 * radius);
      sunGradient[a] = (hi.sunVisibility - lo.sunVisibility) / (2 * radius);
    }
    return { ...blend, gradient, sunGradient };
  }

  // Lights `mesh` (its material must be a MeshLambertMaterial, cloned here so meshes do not share probes) with
  // the probes' field around `point` (default: the centre of its world bounding box) over `radius` (default: its
  // geometry's bounding sphere in world units). Returns the field; throws when no valid probe is near.
  lightObject(mesh, point = null, radius = null) {
    mesh.updateWorldMatrix(true, false);
    if (!point) point = new Box3().setFromObject(mesh).getCenter(new Vector3()).toArray();
    if (radius === null) {
      if (!mesh.geometry.boundingSphere) mesh.geometry.computeBoundingSphere();
      radius = mesh.geometry.boundingSphere.radius * mesh.matrixWorld.getMaxScaleOnAxis();
    }
    const field = this.field(point, radius);
    if (field.probes === 0) throw new Error(`${LIGHT_PROBES}: no valid probe near ${point.join(',')}`);
    mesh.material = mesh.material.clone();
    const emitters = this.emitters.length ? emitterUniforms(this.emitters, visibilityField(this, point, radius)) : null;
    applyProbeSh(mesh.material, field.coefficients, { centre: point, gradient: field.gradient, emitters, sun: this.sun,
                                                      sunVisibility: field.sunVisibility, sunGradient: field.sunGradient });
    return field;
  }
}

// Adds π × max(0, shGetIrradianceAt(n, sh(p))) to a Lambert (or any lit) material's indirect irradiance, n the
// world normal, sh(p) = coefficients + (p − centre)·gradient at the fragment's world point p (without `field`:
// the coefficients everywhere): three.js's own light-probe term, per material instead of per scene, clamped at 0
// as irview; plus, with field.emitters (irbake_probe_emitters.js, emitterUniforms), the exact emitters' π × E/π.
// With `field.sun` (a sun level) its sun is taken out of sh(p) at the visibility
// v(p) = clamp(sunVisibility + (p − centre)·sunGradient, 0, 1) and added exactly (irbake_probe_sun.js, SUN_SHADER).
export function applyProbeSh(material, coefficients, field = null) {
  const vec3s = (a, from) => [...Array(9)].map((_, k) => new Vector3(a[from + 3 * k], a[from + 3 * k + 1], a[from + 3 * k + 2]));
  const gradient = [];
  for (let a = 0; a < 3; ++a) gradient.push(...vec3s(field ? field.gradient[a] : new Float64Array(27), 0));
  material.userData.irbakeProbeSh = { value: vec3s(coefficients, 0) };
  material.userData.irbakeProbeGradient = { value: gradient };
  material.userData.irbakeProbeCentre = { value: new Vector3(...(field ? field.centre : [0, 0, 0])) };
  material.userData.irbakeSun = sunUniforms(field?.sun ?? null, field?.sunVisibility ?? 0, field?.sunGradient ?? [0, 0, 0]);
  const emitters = field?.emitters?.triangles > 0 ? field.emitters : null;
  if (emitters) {
    const vectors = (a, size, Type) => [...Array(a.length / size)].map((_, i) => new Type(...a.slice(size * i, size * i + size)));
    material.userData.irbakeEmitterPositions = { value: vectors(emitters.positions, 3, Vector3) };
    material.userData.irbakeEmitterRadiance = { value: vectors(emitters.radiance, 3, Vector3) };
    material.userData.irbakeEmitterVisibility = { value: vectors(emitters.visibility, 4, Vector4) };
  }
  material.onBeforeCompile = shader => {
    shader.uniforms.irbakeProbeSh = material.userData.irbakeProbeSh;
    if (emitters)
      for (const name of ['irbakeEmitterPositions', 'irbakeEmitterRadiance', 'irbakeEmitterVisibility'])
        shader.uniforms[name] = material.userData[name];
    shader.uniforms.irbakeProbeGradient = material.userData.irbakeProbeGradient;
    shader.uniforms.irbakeProbeCentre = material.userData.irbakeProbeCentre;
    Object.assign(shader.uniforms, material.userData.irbakeSun);
    const anchor = '#include <lights_fragment_maps>', vertexAnchor = '#include <project_vertex>';
    if (!shader.fragmentShader.includes(anchor)) throw new Error(`${LIGHT_PROBES}: this three.js has no ${anchor}`);
    if (!shader.vertexShader.includes(vertexAnchor)) throw new Error(`${LIGHT_PROBES}: this three.js has no ${vertexAnchor}`);
    shader.vertexShader = shader.vertexShader
      .replace('void main() {', 'uniform vec3 irbakeProbeCentre;\nvarying vec3 irbakeProbeOffset;\nvoid main() {')
      .replace(vertexAnchor, `${vertexAnchor}
  irbakeProbeOffset = ( modelMatrix * vec4( transformed, 1.0 ) ).xyz - irbakeProbeCentre;`);
    shader.fragmentShader = shader.fragmentShader
      .replace('void main() {', `uniform vec3 irbakeProbeSh[ 9 ];\nuniform vec3 irbakeProbeGradient[ 27 ];\n${SUN_SHADER.uniforms}
varying vec3 irbakeProbeOffset;\nvoid main() {`)
      .replace(anchor, `${anchor}
  vec3 irbakeN = transformNormalByInverseViewMatrix( geometryNormal, viewMatrix );
  ${SUN_SHADER.visibility}
  vec3 irbakeSh[ 9 ];
  for ( int k = 0; k < 9; ++ k )
    irbakeSh[ k ] = irbakeProbeSh[ k ] + irbakeProbeOffset.x * irbakeProbeGradient[ k ]
                  + irbakeProbeOffset.y * irbakeProbeGradient[ 9 + k ] + irbakeProbeOffset.z * irbakeProbeGradient[ 18 + k ]
                  - irbakeSunV * irbakeSunSh[ k ];
  irradiance += PI * ( max( shGetIrradianceAt( irbakeN, irbakeSh ), vec3( 0.0 ) ) + ${SUN_SHADER.direct} );`);
    if (emitters)
      shader.fragmentShader = shader.fragmentShader
        .replace('void main() {', `uniform vec3 irbakeProbeCentre;\n${emitterGlsl(emitters.triangles)}\nvoid main() {`)
        .replace(anchor, `${anchor}
  irradiance += PI * irbakeExactEmitterLight( irbakeProbeCentre + irbakeProbeOffset,
    normalize( transformNormalByInverseViewMatrix( geometryNormal, viewMatrix ) ), irbakeProbeOffset );`);
  };
  material.customProgramCacheKey = () => `irbake-light-probes-field-${emitters ? emitters.triangles : 0}`;
  material.needsUpdate = true;
}

// A blend's coefficients as three.js's SphericalHarmonics3 (for a LightProbe of intensity π, which lights a whole
// scene rather than one object).
export function toSphericalHarmonics3(coefficients) {
  return new SphericalHarmonics3().fromArray(Array.from(coefficients));
}

function fail(field, message) { throw new Error(`${LIGHT_PROBES}${field ? '.' + field : ''}: ${message}`); }

function threeNumbers(ext, key) {
  const v = ext[key];
  if (!Array.isArray(v) || v.length !== 3 || !v.every(x => typeof x === 'number')) fail(key, 'needs 3 numbers');
  if (!v.every(x => Number.isFinite(Math.fround(x)))) fail(key, 'not finite');  // as 32-bit floats, as irview reads them
  return v;
}

// The grid of a parsed glTF JSON whose accessors `accessor(i)` resolves (a three.js BufferAttribute). Throws an
// Error naming the field for a grid that does not fit, as irbake's reader (readLightProbes) does.
export async function readProbeGrid(json, accessor) {
  const ext = json.extensions?.[LIGHT_PROBES];
  if (!ext || typeof ext !== 'object') fail('', 'no extension');
  const origin = threeNumbers(ext, 'origin').map(Math.fround);
  const counts = threeNumbers(ext, 'counts');
  for (const c of counts) if (!(c >= 1 && Number.isInteger(c) && c <= 1e6)) fail('counts', `${c} is not a whole number from 1 to 10^6`);
  const n = counts[0] * counts[1] * counts[2];
  if (n > 1e8) fail('counts', 'more than 10^8 probes');
  // A positive finite 32-bit float, as irview reads it: 1e-50 would be 0 and 1e39 Infinity.
  const spacing = typeof ext.spacing === 'number' ? Math.fround(ext.spacing) : NaN;
  if (!(spacing > 0) || !Number.isFinite(spacing)) fail('spacing', 'needs a positive finite number');
  checkProbeGridPlace(origin, spacing, counts);
  // Accessor ext[key] (field `prefix + key` in messages) of componentType `component` and `type`, `count`
  // elements (null: any), as a typed array.
  const readFrom = (holder, prefix) => async (key, component, type, count) => {
    const index = holder[key];
    key = prefix + key;
    if (!Number.isInteger(index)) fail(key, 'no accessor index');
    const def = json.accessors?.[index];
    if (!def) fail(key, `accessor ${index} does not exist`);
    if (def.componentType !== component || def.type !== type)
      fail(key, `accessor of componentType ${def.componentType} ${def.type}, expected ${component} ${type}`);
    if (count === null) count = def.count;
    if (def.count !== count) fail(key, `${def.count} elements, the grid needs ${count}`);
    // An accessor without a buffer view is zeros (glTF 2.0, 3.6.2.1), as optimisers write an all-zero one.
    if (def.bufferView !== undefined) {
      const view = json.bufferViews?.[def.bufferView];
      const bytes = (def.byteOffset ?? 0) + 4 * COMPONENTS[type] * count;
      if (!view || (view.byteStride === undefined && bytes > view.byteLength))
        fail(key, `accessor ${index} needs ${bytes} bytes of its buffer view, which has ${view?.byteLength ?? 'none'}`);
    }
    let attribute;
    try {
      attribute = await accessor(index);
    } catch (e) {
      fail(key, `accessor ${index} cannot be read: ${e.message}`);
    }
    const values = new (component === FLOAT ? Float32Array : Uint32Array)(count * COMPONENTS[type]);
    for (let i = 0; i < count; ++i)
      for (let c = 0; c < COMPONENTS[type]; ++c) values[i * COMPONENTS[type] + c] = attribute.getComponent(i, c);
    return values;
  };
  const read = readFrom(ext, '');
  const coefficients = await read('coefficients', FLOAT, 'VEC3', 9 * n);
  const offsets = await read('offsets', FLOAT, 'VEC3', n);
  const validity = await read('valid', FLOAT, 'SCALAR', n);
  const valid = new Uint8Array(n);
  for (let i = 0; i < n; ++i) {
    let finite = Number.isFinite(offsets[3 * i]) && Number.isFinite(offsets[3 * i + 1]) && Number.isFinite(offsets[3 * i + 2]);
    for (let k = 0; k < 27; ++k) finite = finite && Number.isFinite(coefficients[27 * i + k]);
    if (!finite) fail('', `probe ${i} has a non-finite coefficient or offset`);
    checkProbeOffset(offsets, i, spacing);
    if (validity[i] !== 0 && validity[i] !== 1) fail('valid', `probe ${i} holds ${validity[i]} (0 or 1)`);
    valid[i] = validity[i];
  }
  const sun = ext.sun === undefined ? null : await readSunLevel(ext, counts, readFrom(ext.sun ?? {}, 'sun.'));
  const emitters = ext.emitters === undefined ? [] : await readEmitters(ext, n, readFrom);
  return new IrbakeProbeGrid({ origin, spacing, counts, coefficients, offsets, valid, sun, emitters });
}

// The loader plugin: after the document loads, gltf.userData.irbakeLightProbes is the grid (null without the
// extension); a malformed grid rejects the load.
export class IrbakeLightProbesExtension {
  constructor(parser) {
    this.parser = parser;
    this.name = LIGHT_PROBES;
    this.grid = null;
  }

  async afterRoot(result) {
    result.userData ??= {};
    result.userData.irbakeLightProbes = null;
    if (!this.parser.json.extensions?.[LIGHT_PROBES]) return;
    this.grid = await readProbeGrid(this.parser.json, i => this.parser.getDependency('accessor', i));
    result.userData.irbakeLightProbes = this.grid;
  }
}
