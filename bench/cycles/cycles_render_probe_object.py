"""cycles_render.py (../shared/tools/cycles) with one object seen by camera rays only, optionally under a uniform
sky: what a probe-lit object is (it neither shadows nor lights the scene around it, nor does the scene see it).

usage: blender -b --factory-startup --python bench/cycles/cycles_render_probe_object.py -- --object NAME \
           [--sky R,G,B] [--cycles-dir ../shared/tools/cycles] [every cycles_render.py option]

Objects whose name starts with NAME keep camera visibility and lose diffuse, glossy, transmission, volume and
shadow ray visibility. --sky R,G,B sets the world's radiance as cycles_render_sky.py does (`irbake --sky`).
"""
import importlib.util
import os
import sys


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    name, sky, cycles_dir, rest = None, None, None, []
    i = 0
    while i < len(argv):
        if argv[i] in ("--object", "--sky", "--cycles-dir"):
            value = argv[i + 1]
            if argv[i] == "--object":
                name = value
            elif argv[i] == "--sky":
                sky = [float(x) for x in value.split(",")]
            else:
                cycles_dir = value
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    if not name:
        sys.exit("cycles_render_probe_object.py: --object NAME is required")
    if sky is not None and len(sky) != 3:
        sys.exit("cycles_render_probe_object.py: --sky needs R,G,B")
    here = os.path.dirname(os.path.abspath(__file__))
    cycles_dir = cycles_dir or os.path.join(here, "..", "..", "..", "shared", "tools", "cycles")
    script = os.path.join(cycles_dir, "cycles_render.py")
    if not os.path.isfile(script):
        sys.exit("cycles_render_probe_object.py: %s not found (--cycles-dir)" % script)
    sys.argv = sys.argv[:sys.argv.index("--") + 1] + rest if "--" in sys.argv else sys.argv
    spec = importlib.util.spec_from_file_location("cycles_render", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    setup_render = module.setup_render

    def setup_render_probe_object(args, scene):
        setup_render(args, scene)
        found = [o for o in scene.objects if o.name.startswith(name)]
        if not found:
            sys.exit("cycles_render_probe_object.py: no object named %s*" % name)
        for o in found:
            o.visible_diffuse = o.visible_glossy = o.visible_transmission = False
            o.visible_volume_scatter = o.visible_shadow = False
            print("CAMERA_ONLY %s" % o.name)
        if sky is not None:
            background = scene.world.node_tree.nodes.get("Background")
            background.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
            background.inputs["Strength"].default_value = 1.0
            print("SKY %.6g %.6g %.6g" % tuple(sky))

    module.setup_render = setup_render_probe_object
    module.main()


main()
