# Imports a `cps export` glTF binary into Blender headless, prints what arrived (objects, actions
# and the animation's frame range) and, with --still, renders one frame from the file's camera.
#
#   cps export intersecting_stack --out /tmp/run.glb
#   blender -b --factory-startup --python scripts/blender-import.py -- /tmp/run.glb \
#       [--still /tmp/still.png --time 0.625 --size 640x360]
#
# Prints "objects N", "actions N", "frames A..B at F fps" and, with --still, "still PATH".
# Exits 1 (with the reason on stderr) when the file does not import, holds no animation, or the
# still cannot be written. Tested with Debian 12's Blender 3.4.1, whose glTF importer needs
# python3-numpy and predates numpy 1.24 (it uses numpy.bool, set below if missing). Blender turns
# glTF's +Y up into +Z up and maps the animation's seconds onto its scene frame rate.
import argparse
import sys

import numpy

if not hasattr(numpy, "bool"):
    numpy.bool = bool  # Blender 3.4's importer predates numpy 1.24's removal of the alias

import bpy  # noqa: E402  (numpy must be patched first)


def fail(message):
    print("blender-import: " + message, file=sys.stderr)
    sys.exit(1)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender-import.py")
    parser.add_argument("glb", help="the file cps export wrote")
    parser.add_argument("--still", help="render one frame (Workbench) to this PNG")
    parser.add_argument("--time", type=float, default=0.0, help="simulated time of the still (s)")
    parser.add_argument("--size", default="640x360", help="still size WxH (pixels)")
    args = parser.parse_args(argv)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        bpy.ops.import_scene.gltf(filepath=args.glb)
    except Exception as e:  # the importer raises RuntimeError with its reason
        fail(f"{args.glb}: {e}")
    scene = bpy.context.scene
    objects = list(scene.objects)
    actions = list(bpy.data.actions)
    if not actions:
        fail(f"{args.glb}: no animation imported")
    start = min(a.frame_range[0] for a in actions)
    end = max(a.frame_range[1] for a in actions)
    fps = scene.render.fps / scene.render.fps_base
    print(f"objects {len(objects)}")
    print(f"actions {len(actions)}")
    print(f"frames {start:g}..{end:g} at {fps:g} fps")

    if args.still:
        cameras = [o for o in objects if o.type == "CAMERA"]
        if not cameras:
            fail(f"{args.glb}: no camera to render the still from")
        width, height = (int(v) for v in args.size.split("x"))
        scene.camera = cameras[0]
        scene.render.engine = "BLENDER_WORKBENCH"
        scene.display.shading.light = "STUDIO"
        scene.display.shading.color_type = "MATERIAL"
        scene.render.resolution_x = width
        scene.render.resolution_y = height
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = "PNG"
        scene.frame_set(int(round(args.time * fps)))
        scene.render.filepath = args.still
        bpy.ops.render.render(write_still=True)
        print(f"still {args.still} (frame {scene.frame_current}, t = {scene.frame_current / fps:g} s)")


main()
