"""cycles_render.py (../shared/tools/cycles) with a uniform sky: the world's background radiance set to
--sky R,G,B (strength 1), which is what `irbake bake --sky R,G,B` means (radiance of every sky direction).

usage: blender -b --factory-startup --python bench/cycles/cycles_render_sky.py -- --sky R,G,B \
           [--cycles-dir ../shared/tools/cycles] [every cycles_render.py option]

The shared script is loaded as a module and run unchanged except for its render set-up, after which the
world (black there) gets the sky. Camera rays that miss the scene then return exactly the sky's radiance:
compare.py leaves those pixels out as background.
"""
import importlib.util
import os
import sys


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    sky, cycles_dir, rest = None, None, []
    i = 0
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
    if sky is None or len(sky) != 3:
        sys.exit("cycles_render_sky.py: --sky R,G,B is required")
    here = os.path.dirname(os.path.abspath(__file__))
    cycles_dir = cycles_dir or os.path.join(here, "..", "..", "..", "shared", "tools", "cycles")
    script = os.path.join(cycles_dir, "cycles_render.py")
    if not os.path.isfile(script):
        sys.exit("cycles_render_sky.py: %s not found (--cycles-dir)" % script)
    sys.argv = sys.argv[:sys.argv.index("--") + 1] + rest if "--" in sys.argv else sys.argv
    spec = importlib.util.spec_from_file_location("cycles_render", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    setup_render = module.setup_render

    def setup_render_with_sky(args, scene):
        setup_render(args, scene)
        background = scene.world.node_tree.nodes.get("Background")
        background.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
        background.inputs["Strength"].default_value = 1.0
        print("SKY %.6g %.6g %.6g" % tuple(sky))

    module.setup_render = setup_render_with_sky
    module.main()


main()
