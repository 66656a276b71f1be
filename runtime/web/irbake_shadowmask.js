// A GLTFLoader plugin for irbake's mixed lighting (docs/export.md, "IRBAKE_shadowmask" and "Mixed lights"):
// the lights a bake left to the client (KHR lights with extras.irbake.mode indirect or shadowmask, listed in
// the root IRBAKE_shadowmask map, and the command line's sun: a "directional" entry there or the root extras
// irbakeSun) are shaded by three.js's own real-time lights, and on every light-mapped material (the static
// surfaces) each light's direct term is multiplied by its channel of the material's mask page:
//   root:     extensions.IRBAKE_shadowmask = { lights: [{ name, light | directional, channel }, ...] }
//   material: extensions.IRBAKE_shadowmask = { index, texCoord: 1 }   (RGBA, linear, value = visibility)
// An indirect light has no mask: it shades unshadowed. Lights three.js gets from KHR_lights_punctual are in
// glTF's units (three.js r155+: physically based, candela and lux, decay 2), so E = I cosθ / r² and I cosθ
// as the bake's. A light's range is three's distance: its window, clamp(1 − (d/range)⁴, 0, 1)², is the one the
// bake applies (docs/units.md, "Light range"), so decay 2 and distance = range are set on every light kept here.
// three's spot cone (smoothstep) differs from glTF's.
// Usage: loader.register(p => (plugin = new IrbakeShadowmaskExtension(p))); after loading, keep the lights
// plugin.isRuntimeLight(light) says, and call plugin.syncLights(root) once the lights are in place (and
// again whenever lights are added, removed or hidden: it maps three's per-type light order to channels).
// Invalid data throws an Error naming the material or entry and the problem.
import { Vector4, DirectionalLight, NoColorSpace, LinearFilter, ShaderChunk } from 'three';
import { composeShaderPatch } from './shader_patch.js';

export const IRBAKE_SHADOWMASK = 'IRBAKE_shadowmask';
const KHR_LIGHTS = 'KHR_lights_punctual';
// The light loops' lines after which a light's direct term is scaled (three.js lights_fragment_begin).
const HOOKS = {
  point: { line: 'getPointLightInfo( pointLight, geometryPosition, directLight );', count: 'NUM_POINT_LIGHTS' },
  spot: { line: 'getSpotLightInfo( spotLight, geometryPosition, directLight );', count: 'NUM_SPOT_LIGHTS' },
  directional: { line: 'getDirectionalLightInfo( directionalLight, directLight );', count: 'NUM_DIR_LIGHTS' },
};
const KINDS = Object.keys(HOOKS);
const kindOf = light => (light.isPointLight ? 'point' : light.isSpotLight ? 'spot' : light.isDirectionalLight ? 'directional' : null);

export class IrbakeShadowmaskExtension {
  constructor(parser) {
    this.parser = parser;
    this.name = IRBAKE_SHADOWMASK;
    this.maskedMaterials = 0;   // materials shaded with a mask page (for the page and the tests)
    this.runtimeLights = [];    // the three.js lights the bake left to the client
    // Per light kind, per three.js light index: channel weights (one-hot) and the unshadowed share (1 − Σw).
    this.uniforms = Object.fromEntries(KINDS.map(k => [k, { weights: { value: [] }, bias: { value: [] } }]));
    this.channelOfLight = new Map();  // three.js light → channel 0..3, or -1
    this.root = this.readRoot();
  }

  // The root map: glTF light index → channel, and the sun's entry. Throws on malformed entries.
  readRoot() {
    const json = this.parser.json;
    const khrCount = json.extensions?.[KHR_LIGHTS]?.lights?.length ?? 0;
    const root = json.extensions?.[IRBAKE_SHADOWMASK];
    const byIndex = new Map();
    let sun = null;
    if (root !== undefined) {
      if (!Array.isArray(root?.lights)) throw new Error(`root ${IRBAKE_SHADOWMASK}: "lights" must be an array mapping lights to channels`);
      root.lights.forEach((e, i) => {
        const what = `${IRBAKE_SHADOWMASK}.lights[${i}]`;
        if (!Number.isInteger(e?.channel) || e.channel < 0 || e.channel > 3) throw new Error(`${what}: channel must be an integer 0..3 (got ${JSON.stringify(e?.channel)})`);
        if (e.light !== undefined) {
          if (!Number.isInteger(e.light) || e.light < 0 || e.light >= khrCount)
            throw new Error(`${what}: light ${JSON.stringify(e.light)} is not a ${KHR_LIGHTS} light of the file (it has ${khrCount})`);
          byIndex.set(e.light, e.channel);
        } else if (e.directional !== undefined) {
          sun = { ...directionalOf(e.directional, `${what}.directional`), channel: e.channel };
        } else {
          throw new Error(`${what}: needs "light" (a ${KHR_LIGHTS} index) or "directional"`);
        }
      });
    }
    const extrasSun = json.extras?.irbakeSun;
    if (!sun && extrasSun !== undefined) {
      if (!['baked', 'indirect', 'shadowmask'].includes(extrasSun?.mode)) throw new Error('extras.irbakeSun.mode must be "baked", "indirect" or "shadowmask"');
      if (extrasSun.mode !== 'baked') sun = { ...directionalOf(extrasSun, 'extras.irbakeSun'), channel: -1 };
    }
    return { present: root !== undefined, byIndex, sun };
  }

  // The mask extension of a material, checked; null when it has none.
  maskOf(materialIndex) {
    const def = this.parser.json.materials?.[materialIndex];
    const ext = def?.extensions?.[IRBAKE_SHADOWMASK];
    if (ext === undefined) return null;
    const what = `material ${materialIndex}${def.name ? ` ('${def.name}')` : ''}: ${IRBAKE_SHADOWMASK}`;
    const textures = this.parser.json.textures?.length ?? 0;
    if (!Number.isInteger(ext?.index) || ext.index < 0 || ext.index >= textures) throw new Error(`${what}: index ${JSON.stringify(ext?.index)} is not a texture of the file`);
    const moz = def.extensions?.MOZ_lightmap;
    if (!moz) throw new Error(`${what} on a material without MOZ_lightmap (the mask is read with the light map's UVs)`);
    if ((ext.texCoord ?? 1) !== (moz.texCoord ?? 1)) throw new Error(`${what}: texCoord ${ext.texCoord} is not the light map's (${moz.texCoord ?? 1})`);
    if (!this.root.present) throw new Error(`${what} without the root ${IRBAKE_SHADOWMASK} that maps lights to channels`);
    return ext;
  }

  // The glTF light index of a three.js light GLTFLoader made (through its node), or -1.
  gltfLightIndex(light) {
    for (let o = light; o; o = o.parent) {
      const node = this.parser.associations.get(o)?.nodes;
      if (node === undefined) continue;
      return this.parser.json.nodes?.[node]?.extensions?.[KHR_LIGHTS]?.light ?? -1;
    }
    return -1;
  }

  // Whether a three.js light is one the bake left to the client (else it is in the light map: remove it).
  isRuntimeLight(light) { return this.channelOfLight.has(light); }

  async afterRoot(result) {
    const lights = [];
    result.scene.traverse(o => { if (o.isLight) lights.push(o); });
    for (const light of lights) {
      const index = this.gltfLightIndex(light);
      const mode = light.userData?.irbake?.mode;
      if (this.root.byIndex.has(index)) this.channelOfLight.set(light, this.root.byIndex.get(index));
      else if (mode === 'indirect' || mode === 'shadowmask') this.channelOfLight.set(light, -1);
      if (this.channelOfLight.has(light) && (light.isPointLight || light.isSpotLight)) {
        light.decay = 2;  // the inverse square law, and range's window as the bake's
        const range = this.parser.json.extensions?.[KHR_LIGHTS]?.lights?.[index]?.range;
        if (range !== undefined && !(Number.isFinite(range) && range > 0))
          throw new Error(`${KHR_LIGHTS}.lights[${index}]: range must be a number > 0 (got ${JSON.stringify(range)})`);
        light.distance = range ?? 0;
      }
    }
    if (this.root.sun) {  // the command line's sun: not a KHR light, so made here
      const sun = new DirectionalLight(0xffffff, 1);
      sun.name = 'sun';
      sun.color.setRGB(...this.root.sun.irradiance);
      sun.position.set(...this.root.sun.direction.map(v => -v));
      sun.target.position.set(0, 0, 0);
      result.scene.add(sun, sun.target);
      this.channelOfLight.set(sun, this.root.sun.channel);
    }
    this.runtimeLights = [...this.channelOfLight.keys()];
    const meshes = [];
    result.scene.traverse(o => { if (o.isMesh) meshes.push(o); });
    const patched = new Set();
    for (const mesh of meshes) {
      const index = this.parser.associations.get(mesh.material)?.materials;
      if (index === undefined || patched.has(mesh.material)) continue;
      const def = this.parser.json.materials?.[index];
      if (!def?.extensions?.MOZ_lightmap || this.runtimeLights.length === 0) { this.maskOf(index); continue; }
      const ext = this.maskOf(index);
      let mask = null;
      if (ext) {
        mask = await this.parser.getDependency('texture', ext.index);
        mask.colorSpace = NoColorSpace;                    // linear visibility
        mask.minFilter = mask.magFilter = LinearFilter;    // no mip levels: they would mix in the padding
        mask.generateMipmaps = false;
        mask.needsUpdate = true;
        ++this.maskedMaterials;
      }
      patchMaterial(mesh.material, mask, this.uniforms);
      patched.add(mesh.material);
    }
    this.syncLights(result.scene);
  }

  // three.js numbers each kind's lights in the order it meets them in the scene graph (visible ones; none
  // cast shadows here, so its sort keeps that order): the channel weights follow the same order.
  syncLights(root) {
    const order = Object.fromEntries(KINDS.map(k => [k, []]));
    root.traverseVisible(o => { if (o.isLight && kindOf(o)) order[kindOf(o)].push(o); });
    for (const kind of KINDS) {
      const u = this.uniforms[kind];
      u.weights.value = order[kind].map(l => {
        const c = this.channelOfLight.get(l) ?? -1;
        return new Vector4(c === 0 ? 1 : 0, c === 1 ? 1 : 0, c === 2 ? 1 : 0, c === 3 ? 1 : 0);
      });
      u.bias.value = order[kind].map(l => ((this.channelOfLight.get(l) ?? -1) < 0 ? 1 : 0));
    }
  }
}

function directionalOf(j, what) {
  const finite3 = a => Array.isArray(a) && a.length === 3 && a.every(Number.isFinite);
  if (!finite3(j?.direction) || Math.hypot(...j.direction) === 0) throw new Error(`${what}: needs a finite, non-zero "direction" [x, y, z]`);
  if (!finite3(j.irradiance) || j.irradiance.some(v => v < 0)) throw new Error(`${what}: needs a finite "irradiance" [r, g, b] ≥ 0`);
  const n = Math.hypot(...j.direction);
  return { direction: j.direction.map(v => v / n), irradiance: j.irradiance };
}

// The material's light loops scale each light's directLight.color by dot(mask, weights[i]) + bias[i]. Composes
// with the other plugins' shader patches (shader_patch.js), whichever is set first.
function patchMaterial(material, mask, uniforms) {
  const begin = ShaderChunk.lights_fragment_begin;
  for (const kind of KINDS)
    if (!begin.includes(HOOKS[kind].line)) throw new Error(`three.js lights_fragment_begin changed: ${IRBAKE_SHADOWMASK} needs updating (${kind} lights)`);
  const patch = shader => {
    let chunk = begin;
    let decls = mask ? 'uniform sampler2D irbakeShadowMask;\n' : '';
    for (const kind of KINDS) {
      const { line, count } = HOOKS[kind];
      const w = `irbake_${kind}MaskWeights`, b = `irbake_${kind}MaskBias`;
      shader.uniforms[w] = uniforms[kind].weights;
      shader.uniforms[b] = uniforms[kind].bias;
      decls += `#if ${count} > 0\nuniform vec4 ${w}[ ${count} ];\nuniform float ${b}[ ${count} ];\n#endif\n`;
      chunk = chunk.replace(line, `${line}\n\t\tdirectLight.color *= dot( irbakeMask, ${w}[ i ] ) + ${b}[ i ];`);
    }
    if (mask) shader.uniforms.irbakeShadowMask = { value: mask };
    const read = mask ? 'vec4 irbakeMask = texture2D( irbakeShadowMask, vLightMapUv );' : 'vec4 irbakeMask = vec4( 1.0 );';
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <lightmap_pars_fragment>', `#include <lightmap_pars_fragment>\n${decls}`)
      .replace('#include <lights_fragment_begin>', `${read}\n${chunk}`);
  };
  composeShaderPatch(material, `irbake-shadowmask${mask ? '' : '-none'}`, patch);
}
