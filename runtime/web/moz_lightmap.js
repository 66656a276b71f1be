// A GLTFLoader plugin for MOZ_lightmap as irbake writes it (docs/export.md):
//   material.extensions.MOZ_lightmap = { index, texCoord: 1, intensity,
//                                         extras: { colorSpace: "srgb", irbake: { mozLightmap: "irradiance" } } }
// The 8-bit PNG is sRGB-encoded when extras.colorSpace says so (current irbake exports), linear otherwise.
// three.js treats lightMap as irradiance and shades it with BRDF_Lambert = albedo/π, so lightMapIntensity is
// the factor that makes decode(PNG) the irradiance E: the intensity itself (MOZ_lightmap's own rule), intensity × π
// for an older irbake's (generator irbake, no irradiance marker), whose value was irradiance/π
// (moz_lightmap_rules.js). Materials with a light map become MeshLambertMaterial (a physical material would
// add a specular term the bake does not have).
//
// Directional maps (IRBAKE_lightmap_directional, docs/export.md): a material with it and a normalTexture is
// shaded, per channel, with lightmap(n) = max(0, L0 · (n_g·n) + t·n) (baker/transport/directional.h, as irview's
// view_mesh.frag): L0 the MOZ_lightmap value, t the world-space L1 vector decoded from the three linear PNGs as
// (2 · texel − 1) · scale, n_g the interpolated vertex normal, n the normal after three.js's normal map, both
// taken to world space. The tangent frame: the TANGENT attribute, else per-vertex tangents generated here as
// irview generates them (generateTangents below), not three.js's per-pixel derivative frame.
// A MOZ_lightmap irview refuses (moz_lightmap_rules.js) fails the load with an Error naming the material.
// Option lightmapMode 'l0' leaves the directional extension unused (the plain map), as irview --lightmap-mode l0.
import { MeshLambertMaterial, SRGBColorSpace, NoColorSpace, BufferAttribute, ShaderChunk, Vector3 } from 'three';
import { checkMozLightmap } from './moz_lightmap_rules.js';

const DIRECTIONAL = 'IRBAKE_lightmap_directional';
// three's lightmap term in lights_fragment_maps; the directional shader replaces this line (and fails loudly
// when a three.js version no longer has it).
const LIGHTMAP_LINE = 'vec3 lightMapIrradiance = lightMapTexel.rgb * lightMapIntensity;';

export class MozLightmapExtension {
  constructor(parser, { lightmapMode = 'sh' } = {}) {
    this.parser = parser;
    this.name = 'MOZ_lightmap';
    if (lightmapMode !== 'sh' && lightmapMode !== 'l0') throw new Error(`lightmap mode '${lightmapMode}': sh or l0`);
    this.lightmapMode = lightmapMode;
    this.directionalMaterials = 0;  // materials shaded with L1 (for the page and the tests)
    this.generatedTangents = 0;     // meshes that had no TANGENT and got generated tangents
  }

  lightmapOf(materialIndex) {
    const def = this.parser.json.materials?.[materialIndex];
    return def?.extensions?.[this.name];
  }

  // The directional extension of a material when it will be used: sh mode, a light map and a normal map.
  directionalOf(materialIndex) {
    const def = this.parser.json.materials?.[materialIndex];
    const ext = def?.extensions?.[DIRECTIONAL];
    if (this.lightmapMode !== 'sh' || !this.lightmapOf(materialIndex) || !ext || def.normalTexture === undefined) return null;
    if (!Array.isArray(ext.l1) || ext.l1.length !== 3) throw new Error(`material ${materialIndex}: ${DIRECTIONAL}.l1 needs 3 entries`);
    return ext;
  }

  getMaterialType(materialIndex) {
    return this.lightmapOf(materialIndex) ? MeshLambertMaterial : null;
  }

  extendMaterialParams(materialIndex, params) {
    const moz = this.lightmapOf(materialIndex);
    if (!moz) return Promise.resolve();
    // GLTFLoader filled metallic-roughness parameters a Lambert material does not have.
    for (const key of ['metalness', 'roughness']) delete params[key];
    // Refused as irview refuses it (a negative or NaN intensity, a texture the file lacks, another UV set).
    const { index, texCoord, irradiance } = checkMozLightmap(this.parser.json, materialIndex, moz);
    const srgb = moz.extras?.colorSpace === 'srgb';
    params.lightMapIntensity = irradiance;
    return this.parser.assignTexture(params, 'lightMap', { index, texCoord }, srgb ? SRGBColorSpace : NoColorSpace);
  }

  // After the scene is built: every mesh whose material carries a used directional extension gets tangents
  // (when it has none) and the directional shader.
  async afterRoot(result) {
    const meshes = [];
    result.scene.traverse(o => { if (o.isMesh) meshes.push(o); });
    const shaded = new Set();
    for (const mesh of meshes) {
      const association = this.parser.associations.get(mesh.material);
      const index = association?.materials;
      if (index === undefined) continue;
      const ext = this.directionalOf(index);
      if (!ext) continue;
      const def = this.parser.json.materials[index];
      const uvName = uvAttributeName(def.normalTexture.texCoord ?? 0);
      if (!mesh.geometry.attributes.tangent) {
        if (!mesh.geometry.attributes[uvName] || !mesh.geometry.attributes.normal)
          throw new Error(`mesh ${mesh.name}: a directional light map needs NORMAL and the normal map's ${uvName}`);
        splitMirroredUvVertices(mesh.geometry, uvName);
        mesh.geometry.setAttribute('tangent', generateTangents(mesh.geometry, uvName));
        ++this.generatedTangents;
      }
      // GLTFLoader flipped normalScale.y for the derivative frame it chose when TANGENT was missing; with
      // tangents the glTF scale applies as written (B = cross(N, T)·w points where v decreases).
      const scale = def.normalTexture.scale ?? 1;
      mesh.material.normalScale.set(scale, scale);
      if (shaded.has(mesh.material)) continue;
      shaded.add(mesh.material);
      const l1 = await Promise.all(ext.l1.map(async e => {
        const texture = await this.parser.getDependency('texture', e.index);
        texture.colorSpace = NoColorSpace;  // linear values, no sRGB curve
        return texture;
      }));
      if (ext.l1.some(e => (e.texCoord ?? 1) !== ((this.lightmapOf(index).texCoord) ?? 1)))
        throw new Error(`material ${index}: ${DIRECTIONAL} pages must use the light map's texCoord`);
      makeDirectional(mesh.material, l1, ext.l1.map(e => e.scale ?? 1));
      ++this.directionalMaterials;
    }
  }
}

function uvAttributeName(texCoord) { return texCoord === 0 ? 'uv' : `uv${texCoord}`; }

// The light-map term of a Lambert material becomes max(0, L0 (n_g·n) + t·n) (times π: three's irradiance).
function makeDirectional(material, l1, scales) {
  if (!ShaderChunk.lights_fragment_maps.includes(LIGHTMAP_LINE))
    throw new Error('three.js lights_fragment_maps changed: the directional light-map shader needs updating');
  material.onBeforeCompile = shader => {
    shader.uniforms.irbakeL1x = { value: l1[0] };
    shader.uniforms.irbakeL1y = { value: l1[1] };
    shader.uniforms.irbakeL1z = { value: l1[2] };
    shader.uniforms.irbakeL1Scale = { value: new Vector3(...scales) };
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <lightmap_pars_fragment>',
               '#include <lightmap_pars_fragment>\nuniform sampler2D irbakeL1x, irbakeL1y, irbakeL1z;\nuniform vec3 irbakeL1Scale;')
      .replace('#include <lights_fragment_maps>', ShaderChunk.lights_fragment_maps.replace(LIGHTMAP_LINE, `
        // irbake directional light map: normal (after the normal map) and nonPerturbedNormal are view space.
        vec3 irbakeN = inverseTransformDirection( normal, viewMatrix );
        vec3 irbakeT = ( 2.0 * texture2D( irbakeL1x, vLightMapUv ).rgb - 1.0 ) * irbakeL1Scale.x * irbakeN.x
                     + ( 2.0 * texture2D( irbakeL1y, vLightMapUv ).rgb - 1.0 ) * irbakeL1Scale.y * irbakeN.y
                     + ( 2.0 * texture2D( irbakeL1z, vLightMapUv ).rgb - 1.0 ) * irbakeL1Scale.z * irbakeN.z;
        vec3 lightMapIrradiance = max( lightMapTexel.rgb * lightMapIntensity * dot( nonPerturbedNormal, normal )
                                       + PI * irbakeT, vec3( 0.0 ) );`));
  };
  material.customProgramCacheKey = () => 'irbake-directional';
  material.needsUpdate = true;
}

// Per-vertex tangents as irview makes them (runtime/viewer_scene.cpp generateTangents), the way MikkTSpace
// builds them: vertices with the same position, normal and UV welded; per triangle dP/du and dP/dv from the UV
// gradients, at each corner projected on the vertex's tangent plane, normalised, weighted by the corner's
// angle there and summed; Gram–Schmidt against the vertex normal; w such that cross(n, t)·w points where v
// decreases (glTF normal maps: +Y up, UV (0, 0) at the image's top left). In the geometry's own space (three
// transforms it with the normal matrix). A UV mirror's two halves stay apart: the UV triangle's orientation
// is part of the weld key, and splitMirroredUvVertices (run first) copies the vertices both halves share.
export function generateTangents(geometry, uvName) {
  const pos = geometry.attributes.position, nrm = geometry.attributes.normal, uv = geometry.attributes[uvName];
  const count = pos.count;
  const index = geometry.index ? geometry.index.array : Array.from({ length: count }, (_, i) => i);
  const p = i => [pos.getX(i), pos.getY(i), pos.getZ(i)];
  const nOf = i => [nrm.getX(i), nrm.getY(i), nrm.getZ(i)];
  const dot = (x, y) => x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
  const bits = orientationBits(index, uv, count);
  const side = i => (bits[i] === 1 ? 1 : bits[i] === 2 ? -1 : 0);  // 0: no UV area, or both orientations
  const weld = new Uint32Array(count), first = new Map();
  for (let i = 0; i < count; ++i) {
    const key = [...p(i), ...nOf(i), uv.getX(i), uv.getY(i), side(i)].join(',');
    if (!first.has(key)) first.set(key, i);
    weld[i] = first.get(key);
  }
  const inPlane = (v, n) => {
    const d = dot(n, v), w = v.map((x, k) => x - n[k] * d), len = Math.hypot(...w);
    return len > 1e-20 ? w.map(x => x / len) : [0, 0, 0];
  };
  const dPdu = new Float64Array(3 * count), dPdv = new Float64Array(3 * count);
  for (let t = 0; t + 2 < index.length; t += 3) {
    const idx = [index[t], index[t + 1], index[t + 2]];
    const pa = p(idx[0]), pb = p(idx[1]), pc = p(idx[2]);
    const e1 = [0, 1, 2].map(k => pb[k] - pa[k]), e2 = [0, 1, 2].map(k => pc[k] - pa[k]);
    const d1 = [uv.getX(idx[1]) - uv.getX(idx[0]), uv.getY(idx[1]) - uv.getY(idx[0])];
    const d2 = [uv.getX(idx[2]) - uv.getX(idx[0]), uv.getY(idx[2]) - uv.getY(idx[0])];
    const det = d1[0] * d2[1] - d2[0] * d1[1];
    if (!(Math.abs(det) > 1e-20)) continue;
    const orientation = det > 0 ? 1 : -1;
    const su = [0, 1, 2].map(k => (e1[k] * d2[1] - e2[k] * d1[1]) / det);
    const sv = [0, 1, 2].map(k => (e2[k] * d1[0] - e1[k] * d2[0]) / det);
    for (let c = 0; c < 3; ++c) {
      const v = idx[c];
      if (side(v) !== 0 && side(v) !== orientation) continue;
      const n = nOf(v), here = p(v), pn = p(idx[(c + 1) % 3]), pp = p(idx[(c + 2) % 3]);
      const a = inPlane(pn.map((x, k) => x - here[k]), n), b = inPlane(pp.map((x, k) => x - here[k]), n);
      const angle = Math.acos(Math.min(1, Math.max(-1, dot(a, b))));
      const u = inPlane(su, n), w = inPlane(sv, n), o = 3 * weld[v];
      for (let k = 0; k < 3; ++k) { dPdu[o + k] += angle * u[k]; dPdv[o + k] += angle * w[k]; }
    }
  }
  const out = new Float32Array(4 * count);
  for (let i = 0; i < count; ++i) {
    const n = nOf(i), o = 3 * weld[i];
    const du = [dPdu[o], dPdu[o + 1], dPdu[o + 2]], dv = [dPdv[o], dPdv[o + 1], dPdv[o + 2]];
    let t = du.map((x, k) => x - n[k] * dot(n, du));
    if (!(Math.hypot(...t) > 1e-12)) {  // no UV gradient here: any unit vector orthogonal to the normal
      t = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
      const d = dot(n, t);
      t = t.map((x, k) => x - n[k] * d);
    }
    const len = Math.hypot(...t);
    t = t.map(x => x / len);
    const b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]];
    out.set([...t, dot(b, dv) > 0 ? -1 : 1], 4 * i);
  }
  return new BufferAttribute(out, 4);
}

// Twice the signed UV area of triangle t: > 0 counter-clockwise, < 0 mirrored.
function uvDeterminant(index, uv, t) {
  const a = index[t], b = index[t + 1], c = index[t + 2];
  return (uv.getX(b) - uv.getX(a)) * (uv.getY(c) - uv.getY(a)) - (uv.getX(c) - uv.getX(a)) * (uv.getY(b) - uv.getY(a));
}

// Per vertex: which UV orientations its triangles have (bit 0: counter-clockwise, bit 1: mirrored).
function orientationBits(index, uv, count) {
  const bits = new Uint8Array(count);
  for (let t = 0; t + 2 < index.length; t += 3) {
    const det = uvDeterminant(index, uv, t);
    if (!(Math.abs(det) > 1e-20)) continue;
    const bit = det > 0 ? 1 : 2;
    for (let k = 0; k < 3; ++k) bits[index[t + k]] |= bit;
  }
  return bits;
}

// MikkTSpace's vertex split (irview: splitMirroredUvVertices): every vertex that triangles of both UV
// orientations share (a mirror line) is copied, with every attribute, and the mirrored triangles use the
// copy. In place; an unindexed geometry shares no vertex.
export function splitMirroredUvVertices(geometry, uvName) {
  if (!geometry.index) return 0;
  const uv = geometry.attributes[uvName], count = geometry.attributes.position.count;
  const index = Array.from(geometry.index.array);
  const bits = orientationBits(index, uv, count);
  const copyOf = new Map();
  for (let i = 0; i < count; ++i) if (bits[i] === 3) copyOf.set(i, count + copyOf.size);
  if (copyOf.size === 0) return 0;
  for (let t = 0; t + 2 < index.length; t += 3)
    if (uvDeterminant(index, uv, t) < -1e-20)
      for (let k = 0; k < 3; ++k) if (copyOf.has(index[t + k])) index[t + k] = copyOf.get(index[t + k]);
  const sources = [...copyOf.keys()];
  for (const name of Object.keys(geometry.attributes)) {
    const a = geometry.attributes[name], size = a.itemSize;
    // Stored values (normalised integers stay integers), interleaved or not.
    const raw = a.isInterleavedBufferAttribute ? a.data.array : a.array;
    const stride = a.isInterleavedBufferAttribute ? a.data.stride : size, offset = a.isInterleavedBufferAttribute ? a.offset : 0;
    const at = (i, k) => raw[i * stride + offset + k];
    const array = new raw.constructor((count + sources.length) * size);
    for (let i = 0; i < count; ++i) for (let k = 0; k < size; ++k) array[i * size + k] = at(i, k);
    sources.forEach((from, j) => { for (let k = 0; k < size; ++k) array[(count + j) * size + k] = at(from, k); });
    geometry.setAttribute(name, new BufferAttribute(array, size, a.normalized));
  }
  geometry.setIndex(index);
  return sources.length;
}
