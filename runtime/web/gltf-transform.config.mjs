// glTF-Transform CLI configuration that keeps irbake's light maps (docs/export.md, "Optimisers"):
//   BUILD/web/node_modules/.bin/gltf-transform optimize in.gltf out.glb --config runtime/web/gltf-transform.config.mjs
// (the command comes first: `gltf-transform --config FILE optimize` is "Unknown command --config")
// registers MOZ_lightmap, IRBAKE_lightmap_directional, IRBAKE_shadowmask, IRBAKE_light_probes and IRBAKE_lightmap_scenarios (gltf_transform_irbake.mjs) beside every extension the
// CLI knows (a config's list replaces the CLI's, so ALL_EXTENSIONS is repeated here). The packages come from the
// installation the CLI runs from (or IRBAKE_WEB_MODULES=BUILD/web), so the classes are the CLI's own.
import { defineIrbakeExtensions, findModulesDir, importPackage } from './gltf_transform_irbake.mjs';

const modules = findModulesDir();
const core = await importPackage(modules, '@gltf-transform/core');
const { ALL_EXTENSIONS } = await importPackage(modules, '@gltf-transform/extensions');
const { MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes, IrbakeLightmapScenarios } = defineIrbakeExtensions(core);

export default { extensions: [...ALL_EXTENSIONS, MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes,
                             IrbakeLightmapScenarios] };
