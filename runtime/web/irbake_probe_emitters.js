// The optional exact emitters of IRBAKE_light_probes (docs/export.md, `emitters`; baker/lightmap/probe_emitters.h):
// small uniform emitters the probes' SH leaves out, shaded at each surface point by Lambert's polygon formula
// (E/L = |Σ_e Θ_e (γ_e · n)| / 2 over each triangle clipped to the half-space above the tangent plane, front faces
// only) times the emitter's radiance (Le/π, the SH's units) and its visibility, blended from the probes with the
// coefficients' own weights and, over an object, its centre value plus its secant gradient (as the coefficients).
const FLOAT = 5126, UNSIGNED_INT = 5125;
export const MAX_EMITTER_TRIANGLES = 256;  // in all, as irbake's reader (kMaxExactEmitterTriangles)
const FIELD = 'IRBAKE_light_probes.emitters';

function fail(at, message) { throw new Error(`${FIELD}${at}: ${message}`); }

// The `emitters` array of the extension `ext` for a grid of n probes: [{ positions: Float32Array (9 per triangle),
// radiance: [r, g, b], visibility: Float32Array(n) }]. `readFrom(holder, prefix)` gives a reader of holder's
// accessors (checked types and counts, values as an array). Throws an Error naming the field, as irbake's reader.
export async function readEmitters(ext, n, readFrom) {
  const list = ext.emitters;
  if (!Array.isArray(list)) fail('', 'not an array');
  const out = [];
  let triangles = 0;
  for (let k = 0; k < list.length; ++k) {
    const at = `[${k}]`, e = list[k];
    if (!e || typeof e !== 'object' || Array.isArray(e)) fail(at, 'not an object');
    const read = readFrom(e, `emitters${at}.`);
    const positions = await read('positions', FLOAT, 'VEC3', null);
    const count = positions.length / 3;
    if (count === 0 || count % 3 !== 0) fail(`${at}.positions`, `${count} elements, not a whole number of triangles`);
    triangles += count / 3;
    if (triangles > MAX_EMITTER_TRIANGLES) fail('', `more than ${MAX_EMITTER_TRIANGLES} triangles`);
    if (!positions.every(Number.isFinite)) fail(`${at}.positions`, 'a non-finite position');
    const radiance = e.radiance;
    if (!Array.isArray(radiance) || radiance.length !== 3 || !radiance.every(x => typeof x === 'number')) fail(`${at}.radiance`, 'needs 3 numbers');
    if (!radiance.map(Math.fround).every(Number.isFinite)) fail(`${at}.radiance`, 'not finite');  // as 32-bit floats
    if (radiance.some(x => x < 0)) fail(`${at}.radiance`, 'negative');
    const packed = await read('visibility', UNSIGNED_INT, 'SCALAR', Math.ceil(n / 4));  // a byte each, k/255
    const visibility = new Float32Array(n);
    for (let i = 0; i < n; ++i) visibility[i] = ((packed[i >> 2] >>> (8 * (i & 3))) & 255) / 255;
    out.push({ positions, radiance: radiance.map(Math.fround), visibility });
  }
  return out;
}

// Each emitter's visibility from a blend of IrbakeProbeGrid.interpolate (its `corners`: [probe, weight] pairs).
export function blendVisibility(emitters, blend) {
  return emitters.map(e => blend.corners.reduce((v, [i, w]) => v + w * e.visibility[i], 0));
}

// The emitters' visibility over an object: { centre: [v per emitter], gradient: [3 arrays, per metre] }, the
// secant of the blends at centre ± r (zero along an axis whose blend at either end finds no probe).
export function visibilityField(grid, centre, radius) {
  const emitters = grid.emitters;
  const blend = grid.interpolate(centre);
  const out = { centre: blendVisibility(emitters, blend), gradient: [0, 1, 2].map(() => emitters.map(() => 0)) };
  if (blend.probes === 0 || !(radius > 0)) return out;
  for (let a = 0; a < 3; ++a) {
    const hi = grid.interpolate(centre.map((v, i) => (i === a ? v + radius : v)));
    const lo = grid.interpolate(centre.map((v, i) => (i === a ? v - radius : v)));
    if (hi.probes === 0 || lo.probes === 0) continue;
    const vh = blendVisibility(emitters, hi), vl = blendVisibility(emitters, lo);
    out.gradient[a] = vh.map((v, e) => (v - vl[e]) / (2 * radius));
  }
  return out;
}

// The shader's per-triangle uniform values: positions (3 per triangle), radiance, visibility (v, ∂v/∂x, y, z).
export function emitterUniforms(emitters, field) {
  const positions = [], radiance = [], visibility = [];
  emitters.forEach((e, k) => {
    for (let t = 0; t < e.positions.length; t += 9) {
      for (let j = 0; j < 9; ++j) positions.push(e.positions[t + j]);
      radiance.push(...e.radiance);
      visibility.push(field.centre[k], field.gradient[0][k], field.gradient[1][k], field.gradient[2][k]);
    }
  });
  return { triangles: radiance.length / 3, positions, radiance, visibility };
}

// GLSL of irbakeExactEmitterLight(p, n, offset): E/π at world point p with world normal n (unit) from the
// `triangles` triangles of the uniforms above (shaders/probe_emitters.glsl, the same math as irview's).
export function emitterGlsl(triangles) {
  return `
uniform vec3 irbakeEmitterPositions[ ${3 * triangles} ];
uniform vec3 irbakeEmitterRadiance[ ${triangles} ];
uniform vec4 irbakeEmitterVisibility[ ${triangles} ];
float irbakeTriangleFactor( vec3 a, vec3 b, vec3 c, vec3 p, vec3 n ) {
  if ( ! ( dot( p - a, cross( b - a, c - a ) ) > 0.0 ) ) return 0.0;
  vec3 tri[ 3 ] = vec3[ 3 ]( a - p, b - p, c - p );
  vec3 poly[ 4 ];
  int m = 0;
  for ( int i = 0; i < 3; ++ i ) {
    vec3 u = tri[ i ], v = tri[ ( i + 1 ) % 3 ];
    float du = dot( u, n ), dv = dot( v, n );
    if ( du >= 0.0 ) poly[ m ++ ] = u;
    if ( ( du >= 0.0 ) != ( dv >= 0.0 ) ) poly[ m ++ ] = u + ( v - u ) * ( du / ( du - dv ) );
  }
  if ( m < 3 ) return 0.0;
  float sum = 0.0;
  for ( int i = 0; i < m; ++ i ) {
    vec3 u = poly[ i ], v = poly[ ( i + 1 ) % m ], cr = cross( u, v );
    float s = length( cr );
    if ( s > 0.0 ) sum += atan( s, dot( u, v ) ) / s * dot( cr, n );
  }
  return 0.5 * abs( sum );
}
vec3 irbakeExactEmitterLight( vec3 p, vec3 n, vec3 offset ) {
  vec3 sum = vec3( 0.0 );
  for ( int t = 0; t < ${triangles}; ++ t ) {
    vec4 v = irbakeEmitterVisibility[ t ];
    float visibility = clamp( v.x + dot( offset, v.yzw ), 0.0, 1.0 );
    sum += visibility * irbakeEmitterRadiance[ t ] * irbakeTriangleFactor( irbakeEmitterPositions[ 3 * t ],
      irbakeEmitterPositions[ 3 * t + 1 ], irbakeEmitterPositions[ 3 * t + 2 ], p, n );
  }
  return sum;
}
`;
}
