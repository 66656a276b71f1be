// irbake's light-map extensions for glTF-Transform (docs/export.md, "Optimisers"): MOZ_lightmap,
// IRBAKE_lightmap_directional, IRBAKE_shadowmask, IRBAKE_light_probes and IRBAKE_lightmap_scenarios (its pages' and
// layers' textures, its layers' probe accessors) as extension properties whose textures are real Texture references
// (TextureInfo, texCoord 1), so prune, dedup, resize and texture compression treat the maps as used textures and
// keep TEXCOORD_1. Reading refuses what irbake's viewers would show wrongly (a missing texture, a texCoord other
// than 1, a negative or non-numeric intensity, an incomplete directional extension) with an Error naming the
// material. IRBAKE_light_probes (on the root) keeps its accessors as Accessor references; reading refuses a grid
// whose fields or accessors do not fit, naming the field, or that lies where no bake writes one (probe_grid_rules.js,
// with irview's message). Writing refuses an output on which the bake no longer fits its geometry: a light-mapped primitive
// without TEXCOORD_1, or fewer light-mapped triangles than were read (simplification).
//
// The classes must extend the very @gltf-transform/core the caller (the CLI) uses, so they are made from it:
//   const core = await importPackage(modulesDir, '@gltf-transform/core');
//   const { MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes, IrbakeLightmapScenarios } =
//     defineIrbakeExtensions(core);
//   io.registerExtensions([MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes, IrbakeLightmapScenarios]);
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { checkProbeGridPlace, checkProbeOffset } from './probe_grid_rules.js';

export const MOZ_LIGHTMAP = 'MOZ_lightmap';
export const IRBAKE_LIGHTMAP_DIRECTIONAL = 'IRBAKE_lightmap_directional';
export const IRBAKE_LIGHT_PROBES = 'IRBAKE_light_probes';
// The probe grid's accessors (docs/export.md, "IRBAKE_light_probes"): component type, type and elements per probe.
export const PROBE_ACCESSORS = { coefficients: [5126, 'VEC3', 9], offsets: [5126, 'VEC3', 1], valid: [5126, 'SCALAR', 1] };
// The optional sun level's accessors (`sun.<key>`): component type, type, and the element count for a grid of
// `probes` probes whose level has `cells` refined cells of S subdivisions (null: any). `cells` and `fine` are
// omitted together when no cell is refined.
export const SUN_ACCESSORS = {
  sh: [5126, 'VEC3', () => 9], visibility: [5125, 'SCALAR', probes => Math.ceil(probes / 4)], cells: [5125, 'SCALAR', () => null],
  fine: [5125, 'SCALAR', (probes, cells, S) => cells * Math.ceil((S + 1) ** 3 / 32)],
};
// The optional exact emitters' accessors (`emitters[k].<key>`): component type, type, and the element count for a
// grid of `probes` probes (null: any whole number of triangles).
export const EMITTER_ACCESSORS = { positions: [5126, 'VEC3', () => null], visibility: [5125, 'SCALAR', probes => Math.ceil(probes / 4)] };
// An IRBAKE_light_probes definition without its accessor indices (those of `sun` and `emitters` included): what
// read → write keeps.
export function probeFields(def) {
  const fields = Object.fromEntries(Object.entries(def).filter(([k]) => !(k in PROBE_ACCESSORS)));
  if (isObject(def.sun)) fields.sun = Object.fromEntries(Object.entries(def.sun).filter(([k]) => !(k in SUN_ACCESSORS)));
  if (Array.isArray(def.emitters))
    fields.emitters = def.emitters.map(e => Object.fromEntries(Object.entries(e ?? {}).filter(([k]) => !(k in EMITTER_ACCESSORS))));
  return fields;
}
export const IRBAKE_SHADOWMASK = 'IRBAKE_shadowmask';
export const IRBAKE_LIGHTMAP_SCENARIOS = 'IRBAKE_lightmap_scenarios';
// The UV set of every light map (docs/export.md): TEXCOORD_1.
export const LIGHTMAP_TEXCOORD = 1;
const AXES = ['x', 'y', 'z'];

// The folder that holds node_modules/@gltf-transform/core: IRBAKE_WEB_MODULES when set (BUILD/web), else the
// installation the running script comes from (the gltf-transform CLI in BUILD/web/node_modules/.bin).
export function findModulesDir(start = process.env.IRBAKE_WEB_MODULES ?? process.argv[1]) {
  if (!start) throw new Error('gltf_transform_irbake: no modules folder (set IRBAKE_WEB_MODULES to BUILD/web)');
  let dir = fs.existsSync(start) ? fs.realpathSync(start) : path.resolve(start);
  if (fs.existsSync(dir) && !fs.statSync(dir).isDirectory()) dir = path.dirname(dir);
  for (;;) {
    if (fs.existsSync(path.join(dir, 'node_modules', '@gltf-transform', 'core', 'package.json'))) return dir;
    const up = path.dirname(dir);
    if (up === dir) throw new Error(`gltf_transform_irbake: no node_modules/@gltf-transform/core above ${start} ` +
                                    '(scripts/install-web-deps.sh BUILD_DIR installs it; IRBAKE_WEB_MODULES=BUILD/web)');
    dir = up;
  }
}

// Imports a package's ES-module entry from MODULES_DIR/node_modules (the same file the CLI imports, so the same
// classes).
export async function importPackage(modulesDir, name) {
  const root = path.join(modulesDir, 'node_modules', ...name.split('/'));
  const pkg = JSON.parse(fs.readFileSync(path.join(root, 'package.json'), 'utf8'));
  const pick = e => (typeof e === 'string' ? e : e && typeof e === 'object' ? pick(e.import ?? e.default ?? e['.']) : undefined);
  const entry = pick(pkg.exports) ?? pkg.module ?? pkg.main ?? 'index.js';
  return import(pathToFileURL(path.join(root, entry)).href);
}

// "material 3 ('white')": how errors name a material.
function materialLabel(index, def) {
  return `material ${index}${def?.name ? ` ('${def.name}')` : ''}`;
}
function materialName(material, document) {
  const index = document.getRoot().listMaterials().indexOf(material);
  return `material ${index}${material.getName() ? ` ('${material.getName()}')` : ''}`;
}

const isObject = v => v !== null && typeof v === 'object' && !Array.isArray(v);

// The texture a texture-info definition names, or an Error saying why it cannot be used.
function textureOf(context, def, what) {
  const textures = context.jsonDoc.json.textures ?? [];
  if (!isObject(def) || !Number.isInteger(def.index))
    throw new Error(`${what}: no texture index (${JSON.stringify(def?.index)})`);
  if (def.index < 0 || def.index >= textures.length)
    throw new Error(`${what}: texture ${def.index} does not exist (the file has ${textures.length})`);
  const texture = context.textures[textures[def.index].source];
  if (!texture) throw new Error(`${what}: texture ${def.index} has no image`);
  return texture;
}

function checkTexCoord(def, what) {
  const texCoord = def.texCoord ?? LIGHTMAP_TEXCOORD;
  if (texCoord !== LIGHTMAP_TEXCOORD)
    throw new Error(`${what}: texCoord ${JSON.stringify(def.texCoord)}, but light maps use TEXCOORD_${LIGHTMAP_TEXCOORD}`);
}

function checkIntensity(value, what) {
  // Finite as a 32-bit float too, as irview reads it (1e39 would be Infinity).
  if (typeof value !== 'number' || !Number.isFinite(Math.fround(value)) || value < 0)
    throw new Error(`${what}: intensity ${JSON.stringify(value)} (NaN when not a number) must be a finite number ≥ 0`);
}

// Light-mapped triangles per material name, over every node instance of the scenes (GPU instances counted).
// Optimisers that keep a bake valid (weld, join, dedup, quantise, flatten, texture compression) keep these
// counts; simplification lowers them.
export function countLightmappedTriangles(document) {
  const counts = new Map();
  const seen = new Set();
  for (const scene of document.getRoot().listScenes())
    scene.traverse(node => {
      const mesh = node.getMesh();
      if (!mesh || seen.has(node)) return;
      seen.add(node);
      const instanced = node.getExtension('EXT_mesh_gpu_instancing');
      const copies = instanced ? (instanced.listAttributes()[0]?.getCount() ?? 1) : 1;
      for (const prim of mesh.listPrimitives()) {
        const material = prim.getMaterial();
        if (!material?.getExtension(MOZ_LIGHTMAP)) continue;
        const n = prim.getIndices()?.getCount() ?? prim.getAttribute('POSITION')?.getCount() ?? 0;
        const mode = prim.getMode();
        const triangles = mode === 4 ? Math.floor(n / 3) : mode === 5 || mode === 6 ? Math.max(0, n - 2) : 0;
        const name = material.getName() || '(unnamed)';
        counts.set(name, (counts.get(name) ?? 0) + triangles * copies);
      }
    });
  return counts;
}

export function defineIrbakeExtensions(core) {
  const { Extension, ExtensionProperty, PropertyType, TextureInfo, TextureChannel } = core;
  const RGB = TextureChannel.R | TextureChannel.G | TextureChannel.B;

  // MOZ_lightmap on a material: the map texture (TEXCOORD_1) and the intensity that scales its decoded value.
  class Lightmap extends ExtensionProperty {
    static EXTENSION_NAME = MOZ_LIGHTMAP;
    init() {
      this.extensionName = MOZ_LIGHTMAP;
      this.propertyType = 'Lightmap';
      this.parentTypes = [PropertyType.MATERIAL];
    }
    getDefaults() {
      return Object.assign(super.getDefaults(), {
        intensity: 1,
        lightmapTexture: null,
        lightmapTextureInfo: new TextureInfo(this.graph, 'lightmapTextureInfo').setTexCoord(LIGHTMAP_TEXCOORD),
        otherFields: {},  // fields of the definition this class does not model, written back as read
      });
    }
    getIntensity() { return this.get('intensity'); }
    setIntensity(intensity) {
      checkIntensity(intensity, MOZ_LIGHTMAP);
      return this.set('intensity', intensity);
    }
    getTexture() { return this.getRef('lightmapTexture'); }
    getTextureInfo() { return this.getRef('lightmapTexture') ? this.getRef('lightmapTextureInfo') : null; }
    // isColor: irbake's PNG is sRGB-encoded when extras.colorSpace says so (texture compression then treats
    // it as colour).
    setTexture(texture) {
      const srgb = this.getRef('lightmapTextureInfo').getExtras().colorSpace === 'srgb';
      return this.setRef('lightmapTexture', texture, { channels: RGB, isColor: srgb });
    }
    getOtherFields() { return this.get('otherFields'); }
    setOtherFields(fields) { return this.set('otherFields', fields); }
  }

  // IRBAKE_lightmap_directional on a material: three linear L1 pages (x, y, z) with their scales, and the
  // names of their float EXR copies.
  class DirectionalLightmap extends ExtensionProperty {
    static EXTENSION_NAME = IRBAKE_LIGHTMAP_DIRECTIONAL;
    init() {
      this.extensionName = IRBAKE_LIGHTMAP_DIRECTIONAL;
      this.propertyType = 'DirectionalLightmap';
      this.parentTypes = [PropertyType.MATERIAL];
    }
    getDefaults() {
      const defaults = Object.assign(super.getDefaults(), { scales: [1, 1, 1], exr: null, otherFields: {}, l1OtherFields: [{}, {}, {}] });
      for (const a of AXES) {
        defaults[`l1${a}Texture`] = null;
        defaults[`l1${a}TextureInfo`] = new TextureInfo(this.graph, `l1${a}TextureInfo`).setTexCoord(LIGHTMAP_TEXCOORD);
      }
      return defaults;
    }
    // axis 0, 1, 2: x, y, z.
    getL1Texture(axis) { return this.getRef(`l1${AXES[axis]}Texture`); }
    getL1TextureInfo(axis) { return this.getRef(`l1${AXES[axis]}Texture`) ? this.getRef(`l1${AXES[axis]}TextureInfo`) : null; }
    setL1Texture(axis, texture) { return this.setRef(`l1${AXES[axis]}Texture`, texture, { channels: RGB, isColor: false }); }
    getScales() { return this.get('scales').slice(); }
    setScales(scales) {
      if (!Array.isArray(scales) || scales.length !== 3 || !scales.every(s => typeof s === 'number' && Number.isFinite(s) && s >= 0))
        throw new Error(`${IRBAKE_LIGHTMAP_DIRECTIONAL}: scales ${JSON.stringify(scales)} must be 3 finite numbers ≥ 0`);
      return this.set('scales', scales.slice());
    }
    getExr() { return this.get('exr'); }
    setExr(exr) { return this.set('exr', exr ? exr.slice() : null); }
    getOtherFields() { return this.get('otherFields'); }
    setOtherFields(fields) { return this.set('otherFields', fields); }
    getL1OtherFields() { return this.get('l1OtherFields'); }
    setL1OtherFields(fields) { return this.set('l1OtherFields', fields); }
  }

  // Fields a class models; the rest of a definition is kept verbatim.
  const without = (def, keys) => Object.fromEntries(Object.entries(def).filter(([k]) => !keys.includes(k)));

  class MozLightmap extends Extension {
    static EXTENSION_NAME = MOZ_LIGHTMAP;
    extensionName = MOZ_LIGHTMAP;
    prereadTypes = [PropertyType.MESH];
    prewriteTypes = [PropertyType.MESH];
    // Light-mapped triangles per material name as read; the write refuses fewer.
    readTriangles = null;

    createLightmap() { return new Lightmap(this.document.getGraph()); }

    preread(context) {
      (context.jsonDoc.json.materials ?? []).forEach((materialDef, index) => {
        const def = materialDef.extensions?.[MOZ_LIGHTMAP];
        if (def === undefined) return;
        const what = `${materialLabel(index, materialDef)}: ${MOZ_LIGHTMAP}`;
        if (!isObject(def)) throw new Error(`${what} is not an object`);
        const texture = textureOf(context, def, what);
        checkTexCoord(def, what);
        const intensity = 'intensity' in def ? def.intensity : 1;
        checkIntensity(intensity, what);
        const lightmap = this.createLightmap().setIntensity(intensity);
        context.setTextureInfo(lightmap.getRef('lightmapTextureInfo'), def);  // texCoord, extras, sampler
        lightmap.setTexture(texture).setOtherFields(without(def, ['index', 'texCoord', 'intensity', 'extras']));
        context.materials[index].setExtension(MOZ_LIGHTMAP, lightmap);
      });
      return this;
    }

    read() {
      this.readTriangles = countLightmappedTriangles(this.document);
      return this;
    }

    prewrite(context) {
      const materials = this.document.getRoot().listMaterials();
      for (const material of materials) {
        const lightmap = material.getExtension(MOZ_LIGHTMAP);
        if (!lightmap) continue;
        const texture = lightmap.getTexture();
        if (!texture) throw new Error(`${materialName(material, this.document)}: ${MOZ_LIGHTMAP} has no texture`);
        checkIntensity(lightmap.getIntensity(), `${materialName(material, this.document)}: ${MOZ_LIGHTMAP}`);
        const def = context.createTextureInfoDef(texture, lightmap.getTextureInfo());
        def.texCoord = lightmap.getTextureInfo().getTexCoord();  // written even when 0 (normalised in write())
        def.intensity = lightmap.getIntensity();
        Object.assign(def, lightmap.getOtherFields());
        const materialDef = context.jsonDoc.json.materials[context.materialIndexMap.get(material)];
        materialDef.extensions = materialDef.extensions ?? {};
        materialDef.extensions[MOZ_LIGHTMAP] = def;
      }
      return this;
    }

    // After everything is written: every light-mapped primitive reads its map through TEXCOORD_1, and the
    // geometry the bake was made for is still there.
    write(context) {
      const json = context.jsonDoc.json;
      const root = this.document.getRoot();
      const moved = new Map();
      for (const mesh of root.listMeshes()) {
        const meshIndex = context.meshIndexMap.get(mesh);
        if (meshIndex === undefined) continue;
        mesh.listPrimitives().forEach((prim, p) => {
          const material = prim.getMaterial();
          if (!material?.getExtension(MOZ_LIGHTMAP)) return;
          const materialDef = json.materials[context.materialIndexMap.get(material)];
          const primDef = json.meshes[meshIndex].primitives[p];
          const where = `mesh ${meshIndex}${mesh.getName() ? ` ('${mesh.getName()}')` : ''} primitive ${p}, ` +
                        `${materialName(material, this.document)}`;
          moveLightmapToSet1(json, materialDef, primDef, where, moved);
          const uv = primDef.attributes[`TEXCOORD_${LIGHTMAP_TEXCOORD}`], position = primDef.attributes.POSITION;
          if (uv === undefined) throw new Error(`${where}: ${MOZ_LIGHTMAP} needs TEXCOORD_1, which this primitive lacks`);
          if (json.accessors[uv].count !== json.accessors[position].count)
            throw new Error(`${where}: TEXCOORD_1 has ${json.accessors[uv].count} vertices, POSITION ${json.accessors[position].count}`);
        });
      }
      if (this.readTriangles) {
        const now = countLightmappedTriangles(this.document);
        const total = m => [...m.values()].reduce((a, b) => a + b, 0);
        const fewer = [...this.readTriangles].filter(([name, n]) => now.has(name) && now.get(name) < n)
          .map(([name, n]) => `material '${name}' ${n} → ${now.get(name)}`);
        if (fewer.length || total(now) < total(this.readTriangles))
          throw new Error(`${MOZ_LIGHTMAP}: light-mapped triangles ${total(this.readTriangles)} → ${total(now)}` +
                          `${fewer.length ? ` (${fewer.join(', ')})` : ''}: the geometry was simplified, and the baked ` +
                          'light maps no longer fit it. Keep the triangles (gltf-transform optimize --simplify false) ' +
                          'or bake the simplified model.');
      }
      return this;
    }
  }

  class IrbakeLightmapDirectional extends Extension {
    static EXTENSION_NAME = IRBAKE_LIGHTMAP_DIRECTIONAL;
    extensionName = IRBAKE_LIGHTMAP_DIRECTIONAL;
    prereadTypes = [PropertyType.MESH];
    prewriteTypes = [PropertyType.MESH];

    createDirectionalLightmap() { return new DirectionalLightmap(this.document.getGraph()); }

    preread(context) {
      (context.jsonDoc.json.materials ?? []).forEach((materialDef, index) => {
        const def = materialDef.extensions?.[IRBAKE_LIGHTMAP_DIRECTIONAL];
        if (def === undefined) return;
        const what = `${materialLabel(index, materialDef)}: ${IRBAKE_LIGHTMAP_DIRECTIONAL}`;
        if (!isObject(def) || !Array.isArray(def.l1) || def.l1.length !== 3)
          throw new Error(`${what}: l1 needs 3 entries (x, y, z)`);
        if (materialDef.extensions[MOZ_LIGHTMAP] === undefined) throw new Error(`${what} without ${MOZ_LIGHTMAP}`);
        if (def.exr !== undefined && !(Array.isArray(def.exr) && def.exr.length === 3 && def.exr.every(e => typeof e === 'string')))
          throw new Error(`${what}: exr needs 3 file names`);
        const directional = this.createDirectionalLightmap();
        const scales = [];
        def.l1.forEach((entry, axis) => {
          const at = `${what}.l1[${axis}]`;
          const texture = textureOf(context, entry, at);
          checkTexCoord(entry, at);
          const scale = 'scale' in entry ? entry.scale : 1;
          if (typeof scale !== 'number' || !Number.isFinite(scale) || scale < 0)
            throw new Error(`${at}: scale ${JSON.stringify(scale)} must be a finite number ≥ 0`);
          scales.push(scale);
          context.setTextureInfo(directional.getRef(`l1${AXES[axis]}TextureInfo`), entry);
          directional.setL1Texture(axis, texture);
        });
        directional.setScales(scales).setExr(def.exr ?? null)
          .setOtherFields(without(def, ['l1', 'exr']))
          .setL1OtherFields(def.l1.map(e => without(e, ['index', 'texCoord', 'scale', 'extras'])));
        context.materials[index].setExtension(IRBAKE_LIGHTMAP_DIRECTIONAL, directional);
      });
      return this;
    }

    read() { return this; }

    prewrite(context) {
      for (const material of this.document.getRoot().listMaterials()) {
        const directional = material.getExtension(IRBAKE_LIGHTMAP_DIRECTIONAL);
        if (!directional) continue;
        const what = `${materialName(material, this.document)}: ${IRBAKE_LIGHTMAP_DIRECTIONAL}`;
        if (!material.getExtension(MOZ_LIGHTMAP)) throw new Error(`${what} without ${MOZ_LIGHTMAP}`);
        const scales = directional.getScales(), other = directional.getL1OtherFields();
        const l1 = [0, 1, 2].map(axis => {
          const texture = directional.getL1Texture(axis);
          if (!texture) throw new Error(`${what}: no L1${AXES[axis]} texture`);
          const def = context.createTextureInfoDef(texture, directional.getL1TextureInfo(axis));
          def.texCoord = directional.getL1TextureInfo(axis).getTexCoord();
          def.scale = scales[axis];
          return Object.assign(def, other[axis]);
        });
        const def = { l1, ...directional.getOtherFields() };
        if (directional.getExr()) def.exr = directional.getExr();
        const materialDef = context.jsonDoc.json.materials[context.materialIndexMap.get(material)];
        materialDef.extensions = materialDef.extensions ?? {};
        materialDef.extensions[IRBAKE_LIGHTMAP_DIRECTIONAL] = def;
      }
      return this;
    }

    write() { return this; }
  }

  // IRBAKE_light_probes on the root: the grid's fields as read, and its three accessors as real Accessor
  // references, so prune and dedup keep them and the writer renumbers them.
  class LightProbeGrid extends ExtensionProperty {
    static EXTENSION_NAME = IRBAKE_LIGHT_PROBES;
    init() {
      this.extensionName = IRBAKE_LIGHT_PROBES;
      this.propertyType = 'LightProbeGrid';
      this.parentTypes = [PropertyType.ROOT];
    }
    getDefaults() {
      return Object.assign(super.getDefaults(), { coefficients: null, offsets: null, valid: null, sun_sh: null,
                                                  sun_visibility: null, sun_cells: null, sun_fine: null, fields: {} });
    }
    getAccessor(key) { return this.getRef(key); }
    setAccessor(key, accessor) { return this.setRef(key, accessor, { usage: 'OTHER' }); }  // no vertex data: a view of its own
    getFields() { return this.get('fields'); }  // origin, spacing, counts, units, convention, sun's, anything else
    setFields(fields) { return this.set('fields', fields); }
  }

  class IrbakeLightProbes extends Extension {
    static EXTENSION_NAME = IRBAKE_LIGHT_PROBES;
    extensionName = IRBAKE_LIGHT_PROBES;

    createLightProbeGrid() { return new LightProbeGrid(this.document.getGraph()); }

    read(context) {
      const json = context.jsonDoc.json, def = json.extensions?.[IRBAKE_LIGHT_PROBES];
      if (def === undefined) return this;
      const probes = checkProbeGrid(def);
      const grid = this.createLightProbeGrid().setFields(probeFields(def));
      const accessor = (holder, key, ref, componentType, type, count) => {
        const index = holder[key], accessorDef = json.accessors?.[index];
        const what = `${IRBAKE_LIGHT_PROBES}.${refName(ref)}`;
        if (!Number.isInteger(index) || accessorDef === undefined) throw new Error(`${what}: accessor ${JSON.stringify(index)} does not exist`);
        if (count === null) count = accessorDef.count;
        if (accessorDef.componentType !== componentType || accessorDef.type !== type || accessorDef.count !== count)
          throw new Error(`${what}: accessor ${index} is ${accessorDef.count} × ${accessorDef.type} of componentType ` +
                          `${accessorDef.componentType}, the grid needs ${count} × ${type} of ${componentType}`);
        grid.setAccessor(ref, context.accessors[index]);
        return accessorDef.count;
      };
      for (const [key, [componentType, type, per]] of Object.entries(PROBE_ACCESSORS))
        accessor(def, key, key, componentType, type, probes * per);
      const offsets = vec3Elements(context, def.offsets), spacing = Math.fround(def.spacing);
      for (let i = 0; i < probes; ++i) checkProbeOffset(offsets, i, spacing);
      if (def.sun !== undefined) {
        const S = def.sun?.subdivisions;
        if (!isObject(def.sun) || !(Number.isInteger(S) && S >= 1 && S <= 16))
          throw new Error(`${IRBAKE_LIGHT_PROBES}.sun.subdivisions ${JSON.stringify(S)} needs a whole number from 1 to 16`);
        let cells = 0;
        const refined = def.sun.cells !== undefined || def.sun.fine !== undefined;
        for (const [key, [componentType, type, count]] of Object.entries(SUN_ACCESSORS)) {
          if (!refined && (key === 'cells' || key === 'fine')) continue;
          const n = accessor(def.sun, key, `sun_${key}`, componentType, type, count(probes, cells, S));
          if (key === 'cells') cells = n;
        }
      }
      if (def.emitters !== undefined) {
        if (!Array.isArray(def.emitters)) throw new Error(`${IRBAKE_LIGHT_PROBES}.emitters is not an array`);
        def.emitters.forEach((e, k) => {
          if (!isObject(e)) throw new Error(`${IRBAKE_LIGHT_PROBES}.emitters[${k}] is not an object`);
          if (!(Array.isArray(e.radiance) && e.radiance.length === 3 && e.radiance.every(x => typeof x === 'number' && Number.isFinite(x) && x >= 0)))
            throw new Error(`${IRBAKE_LIGHT_PROBES}.emitters[${k}].radiance ${JSON.stringify(e.radiance)} needs 3 finite numbers ≥ 0`);
          for (const [key, [componentType, type, count]] of Object.entries(EMITTER_ACCESSORS)) {
            const n = accessor(e, key, `emitters_${k}_${key}`, componentType, type, count(probes));
            if (key === 'positions' && (n === 0 || n % 3 !== 0))
              throw new Error(`${IRBAKE_LIGHT_PROBES}.emitters[${k}].positions: ${n} elements, not a whole number of triangles`);
          }
        });
      }
      this.document.getRoot().setExtension(IRBAKE_LIGHT_PROBES, grid);
      return this;
    }

    write(context) {
      const grid = this.document.getRoot().getExtension(IRBAKE_LIGHT_PROBES);
      if (!grid) return this;
      const def = { ...grid.getFields() };
      const indexOf = ref => {
        const accessor = grid.getAccessor(ref);
        const index = accessor ? context.accessorIndexMap.get(accessor) : undefined;
        if (index === undefined) throw new Error(`${IRBAKE_LIGHT_PROBES}: the ${refName(ref)} accessor was lost`);
        return index;
      };
      for (const key of Object.keys(PROBE_ACCESSORS)) def[key] = indexOf(key);
      if (def.sun !== undefined) {
        def.sun = { ...def.sun };
        for (const key of Object.keys(SUN_ACCESSORS))
          if (grid.getAccessor(`sun_${key}`) || (key !== 'cells' && key !== 'fine')) def.sun[key] = indexOf(`sun_${key}`);
      }
      if (def.emitters !== undefined)
        def.emitters = def.emitters.map((e, k) => {
          const out = { ...e };
          for (const key of Object.keys(EMITTER_ACCESSORS)) out[key] = indexOf(`emitters_${k}_${key}`);
          return out;
        });
      const json = context.jsonDoc.json;
      json.extensions = json.extensions ?? {};
      json.extensions[IRBAKE_LIGHT_PROBES] = def;
      return this;
    }
  }

  // IRBAKE_shadowmask on a material: its page's RGBA mask (linear, TEXCOORD_1) and the name of its EXR copy.
  class ShadowMask extends ExtensionProperty {
    static EXTENSION_NAME = IRBAKE_SHADOWMASK;
    init() {
      this.extensionName = IRBAKE_SHADOWMASK;
      this.propertyType = 'ShadowMask';
      this.parentTypes = [PropertyType.MATERIAL];
    }
    getDefaults() {
      return Object.assign(super.getDefaults(), {
        maskTexture: null,
        maskTextureInfo: new TextureInfo(this.graph, 'maskTextureInfo').setTexCoord(LIGHTMAP_TEXCOORD),
        exr: null,
        otherFields: {},
      });
    }
    getTexture() { return this.getRef('maskTexture'); }
    getTextureInfo() { return this.getRef('maskTexture') ? this.getRef('maskTextureInfo') : null; }
    // Four channels of data, never colour: texture compression must keep alpha and skip sRGB.
    setTexture(texture) { return this.setRef('maskTexture', texture, { channels: RGB | TextureChannel.A, isColor: false }); }
    getExr() { return this.get('exr'); }
    setExr(exr) { return this.set('exr', exr ?? null); }
    getOtherFields() { return this.get('otherFields'); }
    setOtherFields(fields) { return this.set('otherFields', fields); }
  }

  // The root's light → channel map: [{name, channel 0..3, light (KHR index) | directional {...}}, ...].
  function checkMaskLights(lights, what) {
    if (!Array.isArray(lights) || lights.some(l => !isObject(l) || !Number.isInteger(l.channel) || l.channel < 0 || l.channel > 3))
      throw new Error(`${what}: lights ${JSON.stringify(lights)} must be objects with a channel 0..3`);
  }

  class IrbakeShadowmask extends Extension {
    static EXTENSION_NAME = IRBAKE_SHADOWMASK;
    extensionName = IRBAKE_SHADOWMASK;
    prereadTypes = [PropertyType.MESH];
    prewriteTypes = [PropertyType.MESH];
    lights = null;  // the root extension's definition, written back as read

    createShadowMask() { return new ShadowMask(this.document.getGraph()); }

    preread(context) {
      const root = context.jsonDoc.json.extensions?.[IRBAKE_SHADOWMASK];
      if (root !== undefined) {
        checkMaskLights(root?.lights, `root ${IRBAKE_SHADOWMASK}`);
        this.lights = structuredClone(root);
      }
      (context.jsonDoc.json.materials ?? []).forEach((materialDef, index) => {
        const def = materialDef.extensions?.[IRBAKE_SHADOWMASK];
        if (def === undefined) return;
        const what = `${materialLabel(index, materialDef)}: ${IRBAKE_SHADOWMASK}`;
        if (!isObject(def)) throw new Error(`${what} is not an object`);
        if (!this.lights) throw new Error(`${what} without the root ${IRBAKE_SHADOWMASK} that maps lights to channels`);
        const texture = textureOf(context, def, what);
        checkTexCoord(def, what);
        const mask = this.createShadowMask();
        context.setTextureInfo(mask.getRef('maskTextureInfo'), def);
        mask.setTexture(texture).setExr(def.exr).setOtherFields(without(def, ['index', 'texCoord', 'exr', 'extras']));
        context.materials[index].setExtension(IRBAKE_SHADOWMASK, mask);
      });
      return this;
    }

    read() { return this; }

    prewrite(context) {
      let used = false;
      for (const material of this.document.getRoot().listMaterials()) {
        const mask = material.getExtension(IRBAKE_SHADOWMASK);
        if (!mask) continue;
        const what = `${materialName(material, this.document)}: ${IRBAKE_SHADOWMASK}`;
        if (!mask.getTexture()) throw new Error(`${what} has no texture`);
        const def = context.createTextureInfoDef(mask.getTexture(), mask.getTextureInfo());
        def.texCoord = mask.getTextureInfo().getTexCoord();
        if (mask.getExr()) def.exr = mask.getExr();
        Object.assign(def, mask.getOtherFields());
        const materialDef = context.jsonDoc.json.materials[context.materialIndexMap.get(material)];
        materialDef.extensions = materialDef.extensions ?? {};
        materialDef.extensions[IRBAKE_SHADOWMASK] = def;
        used = true;
      }
      if (used && this.lights) {
        const json = context.jsonDoc.json;
        json.extensions = json.extensions ?? {};
        json.extensions[IRBAKE_SHADOWMASK] = this.lights;
      }
      return this;
    }

    // MOZ_lightmap's write moves the mask's texCoord with the light map's (moveLightmapToSet1).
    write() {
      return this;
    }
  }

  // IRBAKE_lightmap_scenarios on the root (docs/export.md, "Scenarios and light groups"): its page textures and
  // each layer's textures as real Texture references (sRGB colour, as MOZ_lightmap's), each layer's probe
  // coefficients and sun SH as Accessor references, the rest of the definition as read; the writer renumbers them.
  class LightmapScenarios extends ExtensionProperty {
    static EXTENSION_NAME = IRBAKE_LIGHTMAP_SCENARIOS;
    init() {
      this.extensionName = IRBAKE_LIGHTMAP_SCENARIOS;
      this.propertyType = 'LightmapScenarios';
      this.parentTypes = [PropertyType.ROOT];
    }
    getDefaults() { return Object.assign(super.getDefaults(), { fields: {}, pageCount: 0 }); }
    getPageCount() { return this.get('pageCount'); }
    setPageCount(n) { return this.set('pageCount', n); }
    // key: page_P (the default scenario's page P) or layer_L_P; with the sampler its texture had.
    getTexture(key) { return this.getRef(key); }
    getTextureInfo(key) { return this.getRef(`${key}_info`); }
    setTexture(key, texture, textureInfo) {
      this.setRef(`${key}_info`, textureInfo);
      return this.setRef(key, texture, { channels: RGB, isColor: true });
    }
    // key: layer_L_probes or layer_L_sun_sh.
    getAccessor(key) { return this.getRef(key); }
    setAccessor(key, accessor) { return this.setRef(key, accessor, { usage: 'OTHER' }); }
    getFields() { return this.get('fields'); }  // the definition without texture and accessor indices
    setFields(fields) { return this.set('fields', fields); }
  }

  class IrbakeLightmapScenarios extends Extension {
    static EXTENSION_NAME = IRBAKE_LIGHTMAP_SCENARIOS;
    extensionName = IRBAKE_LIGHTMAP_SCENARIOS;
    prewriteTypes = [PropertyType.MESH];
    textureIndices = null;  // key → texture index, made in prewrite (before texture extensions write theirs)

    read(context) {
      const json = context.jsonDoc.json, def = json.extensions?.[IRBAKE_LIGHTMAP_SCENARIOS];
      if (def === undefined) return this;
      const what = IRBAKE_LIGHTMAP_SCENARIOS;
      if (!isObject(def) || !Array.isArray(def.pages) || def.pages.length === 0) throw new Error(`${what}.pages: needs one texture per page`);
      if (!Array.isArray(def.layers) || def.layers.length === 0) throw new Error(`${what}.layers: needs at least one layer`);
      const ext = new LightmapScenarios(this.document.getGraph());
      const texture = (key, index, where) => {
        const t = textureOf(context, { index }, where);
        const info = new TextureInfo(this.document.getGraph(), `${key}_info`);
        context.setTextureInfo(info, { index });
        ext.setTexture(key, t, info);
      };
      def.pages.forEach((index, p) => texture(`page_${p}`, index, `${what}.pages[${p}]`));
      const fields = structuredClone(def);
      delete fields.pages;
      fields.layers = def.layers.map((layer, l) => {
        const where = `${what}.layers[${l}]`;
        if (!isObject(layer) || !Array.isArray(layer.textures) || layer.textures.length !== def.pages.length)
          throw new Error(`${where}.textures: needs one texture per page (${def.pages.length})`);
        if (!Array.isArray(layer.intensity) || layer.intensity.length !== def.pages.length) throw new Error(`${where}.intensity: needs one per page`);
        layer.intensity.forEach(i => checkIntensity(i, where));
        layer.textures.forEach((index, p) => texture(`layer_${l}_${p}`, index, `${where}.textures[${p}]`));
        const kept = without(layer, ['textures', 'probes']);
        const accessor = (key, index, field) => {
          const a = json.accessors?.[index];
          if (!Number.isInteger(index) || a === undefined || a.componentType !== 5126 || a.type !== 'VEC3')
            throw new Error(`${where}.${field}: accessor ${JSON.stringify(index)} is not a FLOAT VEC3 accessor of the file`);
          ext.setAccessor(key, context.accessors[index]);
        };
        if (layer.probes !== undefined) accessor(`layer_${l}_probes`, layer.probes, 'probes');
        if (layer.sun !== undefined) {
          accessor(`layer_${l}_sun_sh`, layer.sun?.sh, 'sun.sh');
          kept.sun = without(layer.sun, ['sh']);
        }
        return kept;
      });
      this.document.getRoot().setExtension(IRBAKE_LIGHTMAP_SCENARIOS, ext.setFields(fields).setPageCount(def.pages.length));
      return this;
    }

    prewrite(context) {
      const ext = this.document.getRoot().getExtension(IRBAKE_LIGHTMAP_SCENARIOS);
      this.textureIndices = new Map();
      if (!ext) return this;
      for (const key of this.textureKeys(ext)) {
        const texture = ext.getTexture(key);
        if (!texture) throw new Error(`${IRBAKE_LIGHTMAP_SCENARIOS}: the texture of ${key} was lost`);
        this.textureIndices.set(key, context.createTextureInfoDef(texture, ext.getTextureInfo(key)).index);
      }
      return this;
    }

    // Every texture key of the definition: page_P, then layer_L_P.
    textureKeys(ext) {
      const pages = [...Array(ext.getPageCount()).keys()];
      return [...pages.map(p => `page_${p}`), ...ext.getFields().layers.flatMap((_, l) => pages.map(p => `layer_${l}_${p}`))];
    }

    write(context) {
      const ext = this.document.getRoot().getExtension(IRBAKE_LIGHTMAP_SCENARIOS);
      if (!ext) return this;
      const fields = ext.getFields(), indices = this.textureIndices;
      const accessorIndex = key => {
        const index = context.accessorIndexMap.get(ext.getAccessor(key));
        if (index === undefined) throw new Error(`${IRBAKE_LIGHTMAP_SCENARIOS}: the accessor of ${key} was lost`);
        return index;
      };
      const pages = [...Array(ext.getPageCount()).keys()].map(p => indices.get(`page_${p}`));
      const def = { ...fields, pages };
      def.layers = fields.layers.map((layer, l) => {
        const out = { ...layer, textures: pages.map((_, p) => indices.get(`layer_${l}_${p}`)) };
        if (ext.getAccessor(`layer_${l}_probes`)) out.probes = accessorIndex(`layer_${l}_probes`);
        if (ext.getAccessor(`layer_${l}_sun_sh`)) out.sun = { ...layer.sun, sh: accessorIndex(`layer_${l}_sun_sh`) };
        return out;
      });
      const json = context.jsonDoc.json;
      json.extensions = json.extensions ?? {};
      json.extensions[IRBAKE_LIGHTMAP_SCENARIOS] = def;
      return this;
    }
  }

  return { MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes, IrbakeLightmapScenarios, Lightmap,
           DirectionalLightmap, ShadowMask, LightProbeGrid, LightmapScenarios };
}

// A reference's field name in messages: sun_sh → sun.sh, emitters_0_positions → emitters[0].positions.
function refName(ref) {
  return ref.replace(/^emitters_(\d+)_/, 'emitters[$1].').replace('_', '.');
}

// The elements of FLOAT VEC3 accessor `index` (a Float32Array) as the reader holds them once it is done: its
// buffer view's values, zeros without one, with its sparse substitutions applied. Extensions read before the reader
// fills in sparse and zero-filled accessors, and optimize writes the mostly-zero probe offsets sparse, so the
// substitutions are applied here (sparse indices and values are tightly packed: glTF 2.0, 3.6.2.3).
function vec3Elements(context, index) {
  const def = context.jsonDoc.json.accessors[index];
  const out = new Float32Array(3 * def.count);
  if (def.bufferView !== undefined) out.set(context.accessors[index].getArray());
  const sparse = def.sparse;
  if (sparse) {
    const bytes = (at, length) => {
      const view = context.bufferViews[at.bufferView];
      return new DataView(view.buffer, view.byteOffset + (at.byteOffset ?? 0), length);
    };
    const indexSize = { 5121: 1, 5123: 2, 5125: 4 }[sparse.indices.componentType];
    const indices = bytes(sparse.indices, sparse.count * indexSize), values = bytes(sparse.values, sparse.count * 12);
    const indexAt = { 1: k => indices.getUint8(k), 2: k => indices.getUint16(2 * k, true), 4: k => indices.getUint32(4 * k, true) }[indexSize];
    for (let k = 0; k < sparse.count; ++k)
      for (let c = 0; c < 3; ++c) out[3 * indexAt(k) + c] = values.getFloat32(12 * k + 4 * c, true);
  }
  return out;
}

// The probe count of an IRBAKE_light_probes definition, or an Error naming the field that is wrong.
export function checkProbeGrid(def) {
  const what = IRBAKE_LIGHT_PROBES;
  if (!isObject(def)) throw new Error(`${what} is not an object`);
  // Finite (and the spacing > 0) as 32-bit floats, as irview reads them: a spacing of 1e-50 is 0 as one, 1e39 Infinity.
  const finite32 = x => typeof x === 'number' && Number.isFinite(Math.fround(x));
  const numbers = (v, n) => Array.isArray(v) && v.length === n && v.every(finite32);
  if (!numbers(def.origin, 3)) throw new Error(`${what}.origin ${JSON.stringify(def.origin)} needs 3 finite numbers`);
  if (!(finite32(def.spacing) && Math.fround(def.spacing) > 0))
    throw new Error(`${what}.spacing ${JSON.stringify(def.spacing)} must be a finite number > 0`);
  if (!numbers(def.counts, 3) || !def.counts.every(c => Number.isInteger(c) && c >= 1))
    throw new Error(`${what}.counts ${JSON.stringify(def.counts)} needs 3 whole numbers ≥ 1`);
  checkProbeGridPlace(def.origin.map(Math.fround), Math.fround(def.spacing), def.counts);
  return def.counts[0] * def.counts[1] * def.counts[2];
}

// Texture infos inside a material definition (every object with an integer 'index': core slots and
// extensions alike).
function textureInfoDefs(value, out = []) {
  if (Array.isArray(value)) value.forEach(v => textureInfoDefs(v, out));
  else if (isObject(value)) {
    if (Number.isInteger(value.index)) out.push(value);
    for (const [k, v] of Object.entries(value)) if (k !== 'extras') textureInfoDefs(v, out);
  }
  return out;
}

// prune renumbers UV sets so that the used ones start at 0: a material whose only texture is its light map
// comes out with the map on TEXCOORD_0. Light maps live on TEXCOORD_1 (docs/export.md), so the written
// primitive gets its light-map UVs back there: the same accessor under both names when set 1 is free (as
// irbake itself writes a primitive without other UVs), else sets k and 1 swap, with every texCoord of the
// material. Only the JSON changes; the document stays as the transforms left it. `moved` remembers per
// material definition what was done, so that its further primitives get the same.
function moveLightmapToSet1(json, materialDef, primDef, where, moved) {
  const lightmap = materialDef.extensions[MOZ_LIGHTMAP];
  const done = moved.get(materialDef);
  const k = done ? done.from : (lightmap.texCoord ?? 0);
  if (k === LIGHTMAP_TEXCOORD) return;
  const from = `TEXCOORD_${k}`, to = `TEXCOORD_${LIGHTMAP_TEXCOORD}`;
  if (primDef.attributes[from] === undefined) throw new Error(`${where}: ${MOZ_LIGHTMAP} reads ${from}, which this primitive lacks`);
  const mode = primDef.attributes[to] === undefined ? 'alias' : 'swap';
  if (done && done.mode !== mode)
    throw new Error(`${where}: the material's primitives disagree on whether TEXCOORD_1 exists; cannot put its light map on TEXCOORD_1`);
  if (mode === 'alias') primDef.attributes[to] = primDef.attributes[from];
  else [primDef.attributes[to], primDef.attributes[from]] = [primDef.attributes[from], primDef.attributes[to]];
  if (done) return;
  moved.set(materialDef, { from: k, mode });
  if (mode === 'alias') {
    const directional = materialDef.extensions[IRBAKE_LIGHTMAP_DIRECTIONAL];
    const mask = materialDef.extensions[IRBAKE_SHADOWMASK];
    for (const info of [lightmap, ...(directional?.l1 ?? []), ...(mask ? [mask] : [])]) info.texCoord = LIGHTMAP_TEXCOORD;
  } else {
    for (const info of textureInfoDefs(materialDef)) {
      const t = info.texCoord ?? 0;
      info.texCoord = t === k ? LIGHTMAP_TEXCOORD : t === LIGHTMAP_TEXCOORD ? k : t;
    }
  }
}
