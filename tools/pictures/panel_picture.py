"""A picture of a sidebar panel as Blender lays it out, drawn from what its ``draw`` records
(devkit/ui_recorder.py): there is no GUI on the build machines, so the layout is drawn with Pillow in
Blender's default dark theme (fields, buttons and labels where ``draw`` puts them, the values the scene
holds), not captured from a window.

    .venv/bin/python -m tools.pictures.panel_picture references --out docs/images/reference_set_panel.png

``references``: the Reference Set panel with the shipped Base Mannequin and the five reference bodies
of ../shared/refmodels typed with their Table 2.3 targets. ``pose``: the Pose panel of the Average RM after
Import BVH of devkit.clips' CMU-named test clip.
"""

import argparse
import os
import pathlib
import sys
import tempfile

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-panel-"))

REPO = pathlib.Path(__file__).resolve().parents[2]
WIDTH, LINE, PAD = 560, 34, 14
THEME = {
    "back": (48, 48, 48),
    "header": (61, 61, 61),
    "field": (29, 29, 29),
    "button": (84, 84, 84),
    "text": (230, 230, 230),
    "dim": (160, 160, 160),
    "accent": (71, 114, 179),
}


def _value(data, prop):
    """What a field shows: a pointer's name, an enum's label, numbers with Blender's precision."""
    value = getattr(data, prop)
    rna = data.bl_rna.properties[prop]
    if rna.type == "POINTER":
        return value.name if value is not None else ""
    if rna.type == "ENUM":
        return rna.enum_items[value].name
    if rna.type == "FLOAT" and getattr(rna, "array_length", 0):
        return [f"{v:g}" for v in value]
    if rna.type == "FLOAT":
        return f"{value:.3g}"
    return str(value)


def tagged_recorder():
    """A devkit Recorder whose every entry also names the layout (row, column, ...) it was drawn into."""
    from devkit.ui_recorder import Recorder

    class Tagged(Recorder):
        def __init__(self, log=None, kind="column"):
            super().__init__(log)
            self.kind = kind

        def _child(self, kind, **kwargs):
            self.log.append((kind, kwargs, self))
            return Tagged(self.log, kind)

        def _tag(self, method, *args, **kwargs):
            result = getattr(super(), method)(*args, **kwargs)
            self.log[-1] = (*self.log[-1][:2], self)
            return result

        def prop(self, *args, **kwargs):
            return self._tag("prop", *args, **kwargs)

        def operator(self, *args, **kwargs):
            return self._tag("operator", *args, **kwargs)

        def label(self, **kwargs):
            return self._tag("label", **kwargs)

    return Tagged()


def layout_lines(log):
    """The recorded layout as lines of items: what a row holds on one line, anything else on a line of its own."""
    lines, last = [], None
    for kind, kw, owner in log:
        if kind not in ("prop", "operator", "label"):
            continue
        if owner is last and owner.kind in ("row", "split"):
            lines[-1].append((kind, kw))
        else:
            lines.append([(kind, kw)])
        last = owner
    return lines


ICONS = {"ADD": "+", "X": "×"}  # icon-only buttons, drawn narrow
ICON_WIDTH = 36


def draw(title, log, path):
    from PIL import Image, ImageDraw, ImageFont

    font_path = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
    font = ImageFont.truetype(font_path, 15) if os.path.isfile(font_path) else ImageFont.load_default()
    lines = layout_lines(log)
    image = Image.new("RGB", (WIDTH, LINE * (len(lines) + 1) + 2 * PAD), THEME["back"])
    pen = ImageDraw.Draw(image)
    pen.rectangle([0, 0, WIDTH, LINE], fill=THEME["header"])
    pen.text((PAD, 8), "▾  " + title, fill=THEME["text"], font=font)
    y = LINE + PAD // 2
    for line in lines:
        cells = []
        for kind, kw in line:
            if kind == "prop" and kw["data"].bl_rna.properties[kw["prop"]].subtype == "FACTOR":
                cells.append(("bar", getattr(kw["data"], kw["prop"])))
            elif kind == "prop":
                value = _value(kw["data"], kw["prop"])
                label = kw.get("text", kw["data"].bl_rna.properties[kw["prop"]].name)
                cells += (
                    [("field", v) for v in value]
                    if isinstance(value, list)
                    else [("field", f"{label}: {value}" if label else value)]
                )
            elif kind == "operator":
                cells.append(("button", kw.get("text", _operator_label(kw["idname"])) or ICONS.get(kw.get("icon"), "")))
            elif kind == "label":
                cells.append(("label", kw.get("text", "")))
        icons = sum(1 for kind, text in cells if kind == "button" and text in ICONS.values())
        x, share = PAD, (WIDTH - 2 * PAD - ICON_WIDTH * icons) / max(len(cells) - icons, 1)
        for cell_kind, text in cells:
            width = ICON_WIDTH if cell_kind == "button" and text in ICONS.values() else share
            box = [x + 2, y + 3, x + width - 2, y + LINE - 5]
            if cell_kind == "bar":
                pen.rounded_rectangle(box, radius=5, fill=THEME["field"])
                pen.rounded_rectangle(
                    [box[0], box[1], box[0] + (box[2] - box[0]) * text, box[3]], radius=5, fill=THEME["accent"]
                )
                text = f"{text:.0%}"
            elif cell_kind != "label":
                pen.rounded_rectangle(box, radius=5, fill=THEME["field" if cell_kind == "field" else "button"])
            pen.text((x + 8, y + 8), str(text)[: int(width / 8)], fill=THEME["text"], font=font)
            x += width
        y += LINE
    path.parent.mkdir(parents=True, exist_ok=True)
    image.save(path)


def _operator_label(idname):
    import bpy

    module, _, name = idname.partition(".")
    return getattr(getattr(bpy.ops, module), name).get_rna_type().name


def references_scene(refmodels):
    """The Reference Set panel's scene: the shipped base, the five bodies, their Table 2.3 targets."""
    import bpy

    from ellimann_addon.blender.bridge.convert import mannequin_to_collection, mesh_from_arrays
    from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
    from ellimann_addon.core.fitting.body_mesh import read_obj
    from ellimann_addon.core.mannequin.model import Mannequin
    from ellimann_addon.core.measurements import MEASUREMENTS
    from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

    props = bpy.context.scene.ellimann_references
    props.base = mannequin_to_collection(
        Mannequin.load(REFERENCE_FOLDER / "base_mannequin.json"), name="Base Mannequin"
    )
    for name, targets in REFERENCE_MEASUREMENTS.items():
        body = read_obj(pathlib.Path(refmodels) / f"{name}.obj", up="z")
        obj = bpy.data.objects.new(name, mesh_from_arrays(name, body.vertices, body.faces))
        bpy.context.scene.collection.objects.link(obj)
        row = props.bodies.add()
        row.body, row.target = obj, [targets[k] for k in MEASUREMENTS]
    props.folder = "/home/studio/reference_sets/fit_models/"
    props.set_name = "My studio's fit models"
    props.sex = "female"
    props.status = "fitting tall_chubby (4 of 5)"
    props.progress = 0.62


def pose_scene():
    """The Average RM rigged, devkit.clips' CMU test clip imported onto it (the operator's own path)."""
    import bpy

    from devkit import bvh, clips
    from ellimann_addon.blender.services.scene import add_mannequin
    from ellimann_addon.core.mannequin.model import Mannequin
    from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

    average = Mannequin.load(REFERENCE_FOLDER / "average.json")
    collection = add_mannequin(average)
    bpy.context.view_layer.objects.active = next(iter(collection.objects))
    bpy.ops.ellimann.add_armature()
    path = pathlib.Path(tempfile.mkdtemp(prefix="ellimann-panel-")) / "cmu_walk.bvh"
    bpy.ops.ellimann.import_bvh(filepath=str(bvh.write_bvh(path, clips.convention_clip("cmu", average.joints))))


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.pictures.panel_picture", description=__doc__.splitlines()[0])
    parser.add_argument("panel", choices=("references", "pose"))
    parser.add_argument("--out", type=pathlib.Path, required=True)
    parser.add_argument("--refmodels", type=pathlib.Path, default=REPO.parent / "shared" / "refmodels")
    args = parser.parse_args(argv)
    import bpy

    import ellimann_addon
    from devkit.ui_recorder import draw_panel
    from ellimann_addon.blender.features.references.panel import ELLIMANN_PT_references
    from ellimann_addon.blender.services.teardown import exit_with

    ellimann_addon.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    if args.panel == "pose":
        from ellimann_addon.blender.features.pose.panel import ELLIMANN_PT_pose

        pose_scene()
        draw("Pose", draw_panel(ELLIMANN_PT_pose, recorder=tagged_recorder()).log, args.out)
    else:
        references_scene(args.refmodels)
        draw("Reference Set", draw_panel(ELLIMANN_PT_references, recorder=tagged_recorder()).log, args.out)
    print(f"wrote {args.out}")
    exit_with(0)


if __name__ == "__main__":
    sys.exit(main())
