"""cycles_bake.py (../shared/tools/cycles) keeping the scene's KHR_lights_punctual lights, so that a level lit by a
sun or a lamp bakes its light into our atlas (the shared script deletes every non-mesh object after import).

usage: blender -b --factory-startup --python bench/cycles/cycles_bake_lights.py -- \
           [--cycles-dir ../shared/tools/cycles] [every cycles_bake.py option]

The shared script is loaded as a module and run unchanged, except that after its glTF import the LIGHT objects
survive its clean-up, and they are set up as cycles_render.py sets them: suns re-oriented from the glTF JSON
(the importer's orientation of a tilted sun is not trusted there), sun angle 0, point and spot radius 0, COMPAT
units (the bake's importer already uses them). compare.py --maps --bake-lights runs it. With --sky R,G,B the
world (black there) gets that uniform radiance, as `irbake bake --sky R,G,B` (compare.py --maps --sky).
"""
import importlib.util
import os
import sys
from types import SimpleNamespace


def load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class _Objects:
    """bpy.data.objects, except that remove() spares LIGHT objects once the scene is imported."""

    def __init__(self, real, state):
        self._real, self._state = real, state

    def remove(self, obj, do_unlink=True):
        if self._state["keep"] and obj.type == "LIGHT":
            return
        self._real.remove(obj, do_unlink=do_unlink)

    def __iter__(self):
        return iter(self._real)

    def __len__(self):
        return len(self._real)

    def __getattr__(self, name):
        return getattr(self._real, name)


class _Data:
    def __init__(self, real, state):
        self._real, self._state = real, state

    def __getattr__(self, name):
        if name == "objects":
            return _Objects(self._real.objects, self._state)
        return getattr(self._real, name)


class _Bpy:
    def __init__(self, real, state):
        self._real, self._state = real, state

    def __getattr__(self, name):
        if name == "data":
            return _Data(self._real.data, self._state)
        return getattr(self._real, name)


def main():
    import bpy
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    cycles_dir, sky, rest, i = None, None, [], 0
    while i < len(argv):
        if argv[i] == "--sky":
            sky = [float(x) for x in argv[i + 1].split(",")]
            i += 2
        elif argv[i] == "--cycles-dir":
            cycles_dir = argv[i + 1]
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    here = os.path.dirname(os.path.abspath(__file__))
    cycles_dir = cycles_dir or os.path.join(here, "..", "..", "..", "shared", "tools", "cycles")
    paths = [os.path.join(cycles_dir, n) for n in ("cycles_bake.py", "cycles_render.py")]
    for p in paths:
        if not os.path.isfile(p):
            sys.exit("cycles_bake_lights.py: %s not found (--cycles-dir)" % p)
    sys.argv = sys.argv[:sys.argv.index("--") + 1] + rest if "--" in sys.argv else sys.argv
    bake = load("cycles_bake", paths[0])
    render = load("cycles_render", paths[1])
    state = {"keep": False}
    bake.bpy = _Bpy(bpy, state)
    import_gltf = bake.import_gltf

    def import_keeping_lights(path):
        import_gltf(path)
        state["keep"] = True
        render.orient_suns(bake.gltf_json(path))
        render.fix_lights(SimpleNamespace(light_radius=0.0))
        lights = [o.name for o in bpy.context.scene.objects if o.type == "LIGHT"]
        print("LIGHTS KEPT %d: %s" % (len(lights), ", ".join(lights)))

    bake.import_gltf = import_keeping_lights
    if sky is not None:
        setup_cycles = bake.setup_cycles

        def setup_cycles_with_sky(scene, args):
            setup_cycles(scene, args)
            background = scene.world.node_tree.nodes.get("Background")
            background.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
            background.inputs["Strength"].default_value = 1.0
            print("SKY %.6g %.6g %.6g" % tuple(sky))

        bake.setup_cycles = setup_cycles_with_sky
    bake.main()


main()
