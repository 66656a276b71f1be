// A GLTFLoader plugin for IRBAKE_lightmap_scenarios (docs/export.md, "Scenarios and light groups"): a bake with
// light groups keeps each group's light as a layer (an 8-bit sRGB PNG and an intensity per page), and the client
// mixes them at run time. Every material with MOZ_lightmap whose texture is page p of the extension's `pages`
// shades with
//   E = Σ_L w_L ⊙ sRGBToLinear(textures_L[p]) × intensity_L[p]
// in place of the MOZ_lightmap value (three.js's lightMapTexel × lightMapIntensity), the layers read with the
// light map's UVs; directional L1 pages and shadow masks (not split into layers) apply on top as before. The
// weights w_L (RGB, ≥ 0) are uniforms every material shares: setWeights / useScenario change them for the next
// render. They start at the default scenario's, which the document's own maps hold.
// Usage: loader.register(p => (plugin = new IrbakeLightmapScenariosExtension(p, { weights, scenario }))), then
// plugin.setWeights({ day: 0.2, street: [1, 0.8, 0.5] }) and render again. Invalid data throws an Error naming
// the field.
import { SRGBColorSpace, Vector3, ShaderChunk } from 'three';
import { composeShaderPatch } from './shader_patch.js';

export const IRBAKE_SCENARIOS = 'IRBAKE_lightmap_scenarios';
// three's light-map read in lights_fragment_maps; the blend replaces the texel it reads (and fails loudly when a
// three.js version no longer has the line).
const TEXEL_LINE = 'vec4 lightMapTexel = texture2D( lightMap, vLightMapUv );';

const finiteNonNegative = v => typeof v === 'number' && Number.isFinite(v) && v >= 0;

// An RGB weight from a number (grey) or [r, g, b], each finite and ≥ 0; throws naming `what`.
export function rgbWeight(w, what) {
  const rgb = typeof w === 'number' ? [w, w, w] : w;
  if (!Array.isArray(rgb) || rgb.length !== 3 || !rgb.every(finiteNonNegative))
    throw new Error(`${what}: a weight is one finite number ≥ 0 or three (R, G, B), got ${JSON.stringify(w)}`);
  return rgb;
}

// "day=0.5;street=1,0.8,0.5" (the viewer's query, irbake relight's --group NAME=W joined by ';') → { day: 0.5, ... }.
export function parseWeights(text) {
  const out = {};
  for (const entry of text.split(';').filter(e => e.length > 0)) {
    const [name, value, extra] = entry.split('=');
    if (!name || value === undefined || extra !== undefined) throw new Error(`weights: '${entry}' is not NAME=W`);
    const numbers = value.split(',').map(v => (v.trim() === '' ? NaN : Number(v)));
    out[name] = numbers.length === 1 ? numbers[0] : numbers;
  }
  return out;
}

// The root extension, checked against the file; null when the file has none.
export function readScenarios(json) {
  const ext = json.extensions?.[IRBAKE_SCENARIOS];
  if (ext === undefined) return null;
  const textures = json.textures?.length ?? 0;
  const isTexture = t => Number.isInteger(t) && t >= 0 && t < textures;
  if (!Array.isArray(ext?.pages) || ext.pages.length === 0 || !ext.pages.every(isTexture))
    throw new Error(`${IRBAKE_SCENARIOS}.pages: needs one texture of the file per light-map page`);
  if (!Array.isArray(ext.layers) || ext.layers.length === 0) throw new Error(`${IRBAKE_SCENARIOS}.layers: needs at least one layer`);
  const names = new Set();
  const layers = ext.layers.map((l, i) => {
    const what = `${IRBAKE_SCENARIOS}.layers[${i}]`;
    if (typeof l?.name !== 'string' || !/^[A-Za-z0-9_-]{1,64}$/.test(l.name) || names.has(l.name))
      throw new Error(`${what}.name: needs a unique name of 1 to 64 of A-Z a-z 0-9 _ -`);
    names.add(l.name);
    for (const key of ['textures', 'intensity'])
      if (!Array.isArray(l[key]) || l[key].length !== ext.pages.length) throw new Error(`${what}.${key}: needs one entry per page (${ext.pages.length})`);
    if (!l.textures.every(isTexture)) throw new Error(`${what}.textures: ${JSON.stringify(l.textures)} names a texture the file lacks`);
    if (!l.intensity.every(finiteNonNegative)) throw new Error(`${what}.intensity: ${JSON.stringify(l.intensity)} must be finite numbers ≥ 0`);
    return { name: l.name, textures: l.textures, intensity: l.intensity };
  });
  if (!Array.isArray(ext.scenarios) || ext.scenarios.length === 0) throw new Error(`${IRBAKE_SCENARIOS}.scenarios: needs the default scenario`);
  const scenarios = ext.scenarios.map((s, i) => {
    const what = `${IRBAKE_SCENARIOS}.scenarios[${i}]`;
    if (typeof s?.name !== 'string' || typeof s.weights !== 'object' || s.weights === null) throw new Error(`${what}: needs a name and weights`);
    for (const name of Object.keys(s.weights)) if (!names.has(name)) throw new Error(`${what}.weights: '${name}' is not a layer of the file`);
    return { name: s.name, weights: Object.fromEntries(layers.map(l => [l.name, rgbWeight(s.weights[l.name] ?? 0, `${what}.weights.${l.name}`)])) };
  });
  const def = ext.default ?? 0;
  if (!Number.isInteger(def) || def < 0 || def >= scenarios.length) throw new Error(`${IRBAKE_SCENARIOS}.default: ${JSON.stringify(def)} is not a scenario of the file`);
  return { pages: ext.pages, layers, scenarios, defaultScenario: def };
}

export class IrbakeLightmapScenariosExtension {
  // weights: { layer: w } over the scenario's; scenario: the starting scenario's name (default: the document's).
  constructor(parser, { weights = null, scenario = null } = {}) {
    this.parser = parser;
    this.name = IRBAKE_SCENARIOS;
    this.blendedMaterials = 0;  // materials shaded with the blend (for the page and the tests)
    this.ext = readScenarios(parser.json);
    this.uniforms = (this.ext?.layers ?? []).map(() => ({ value: new Vector3() }));  // shared by every material
    if (!this.ext) return;
    this.useScenario(scenario ?? this.ext.scenarios[this.ext.defaultScenario].name);
    if (weights) this.setWeights(weights);
  }

  get layers() { return this.ext?.layers.map(l => l.name) ?? []; }
  get scenarios() { return this.ext?.scenarios.map(s => s.name) ?? []; }

  // The weights now, per layer name.
  weights() { return Object.fromEntries(this.layers.map((name, i) => [name, this.uniforms[i].value.toArray()])); }

  // New weights for the layers named ({ name: number | [r, g, b] }); the others keep theirs.
  setWeights(byName) {
    for (const [name, w] of Object.entries(byName)) {
      const i = this.layers.indexOf(name);
      if (i < 0) throw new Error(`${IRBAKE_SCENARIOS}: no layer '${name}' (the file has ${this.layers.join(', ')})`);
      this.uniforms[i].value.set(...rgbWeight(w, `weight of '${name}'`));
    }
  }

  // Every layer's weight from a stored scenario (a layer it does not name: 0).
  useScenario(name) {
    const s = this.ext?.scenarios.find(x => x.name === name);
    if (!s) throw new Error(`${IRBAKE_SCENARIOS}: no scenario '${name}' (the file has ${this.scenarios.join(', ')})`);
    this.setWeights(s.weights);
  }

  async afterRoot(result) {
    if (!this.ext) return;
    if (!ShaderChunk.lights_fragment_maps.includes(TEXEL_LINE))
      throw new Error(`three.js lights_fragment_maps changed: ${IRBAKE_SCENARIOS} needs updating`);
    const meshes = [];
    result.scene.traverse(o => { if (o.isMesh) meshes.push(o); });
    const patched = new Set();
    for (const mesh of meshes) {
      const index = this.parser.associations.get(mesh.material)?.materials;
      const moz = this.parser.json.materials?.[index]?.extensions?.MOZ_lightmap;
      if (index === undefined || !moz || patched.has(mesh.material)) continue;
      const page = this.ext.pages.indexOf(moz.index);
      if (page < 0) continue;  // a map the layers do not cover: shown as it is
      patched.add(mesh.material);
      const textures = await Promise.all(this.ext.layers.map(async l => {
        const texture = await this.parser.getDependency('texture', l.textures[page]);
        texture.colorSpace = SRGBColorSpace;  // sRGB PNGs, as MOZ_lightmap's
        return texture;
      }));
      blendLayers(mesh.material, textures, this.ext.layers.map(l => l.intensity[page]), this.uniforms);
      ++this.blendedMaterials;
    }
  }
}

// The material's light-map texel becomes the layers' blend over lightMapIntensity, so three's
// lightMapTexel × lightMapIntensity (and the directional shader's use of it) is the blend.
function blendLayers(material, textures, intensity, weights) {
  if (!(material.lightMapIntensity > 0)) material.lightMapIntensity = 1;  // only divides the blend now
  const n = textures.length;
  const patch = shader => {
    let decls = '', sum = [];
    for (let i = 0; i < n; ++i) {
      shader.uniforms[`irbakeLayer${i}`] = { value: textures[i] };
      shader.uniforms[`irbakeLayerIntensity${i}`] = { value: intensity[i] };
      shader.uniforms[`irbakeLayerWeight${i}`] = weights[i];
      decls += `uniform sampler2D irbakeLayer${i};\nuniform float irbakeLayerIntensity${i};\nuniform vec3 irbakeLayerWeight${i};\n`;
      sum.push(`irbakeLayerWeight${i} * texture2D( irbakeLayer${i}, vLightMapUv ).rgb * irbakeLayerIntensity${i}`);
    }
    let fragment = shader.fragmentShader.replace('#include <lights_fragment_maps>', ShaderChunk.lights_fragment_maps);
    if (!fragment.includes(TEXEL_LINE)) throw new Error(`${IRBAKE_SCENARIOS}: the material's shader has no light-map read to blend`);
    fragment = fragment.replace(TEXEL_LINE, `${TEXEL_LINE}\n\t\tlightMapTexel.rgb = ( ${sum.join('\n\t\t\t+ ')} ) / lightMapIntensity;`);
    shader.fragmentShader = fragment.replace('#include <lightmap_pars_fragment>', `#include <lightmap_pars_fragment>\n${decls}`);
  };
  composeShaderPatch(material, `irbake-scenarios-${n}`, patch);
}
