"""Write the .blend twins of ``reference_blends/*.json`` with the oldest Blender the manifest promises.

    python3 -m tools.shipped.reference_blends [--folder DIR] [STEM ...]

Blender reads files saved by older versions, never those of newer ones, and Blender 5.0 changed the
file format itself (4.x cannot open a 5.0 file at all). So the shipped twins are saved by the
matrix's oldest lane (``tools.matrix``, Blender 4.2): run under any other Python, this re-runs itself
there, making that lane's venv on first use.
"""

import argparse
import os
import pathlib
import subprocess
import sys

REPO = pathlib.Path(__file__).resolve().parents[2]
FOLDER = REPO / "reference_blends"
STEMS = ("base_mannequin", "small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")


def write_blends(mannequins, folder):
    """One .blend per mannequin (a collection of ellipsoid objects), through the add-on's converter.

    ``mannequins`` maps file stems to mannequins. Needs the bpy module (run it on the oldest Blender).
    """
    import bpy

    import ellimann_addon
    from ellimann_addon.blender.bridge import convert

    folder = pathlib.Path(folder)
    bpy.context.preferences.filepaths.save_version = 0  # no .blend1 backups of the files it replaces
    ellimann_addon.register()
    try:
        for stem, mannequin in mannequins.items():
            bpy.ops.wm.read_homefile(use_empty=True)
            convert.mannequin_to_collection(mannequin, name=mannequin.name)
            bpy.ops.wm.save_as_mainfile(filepath=str(folder / f"{stem}.blend"), compress=True)
    finally:
        ellimann_addon.unregister()


def oldest_lane_python():
    from ..matrix.lanes import LANES, ensure_venv

    lane = LANES[0]
    with open(os.devnull, "w") as quiet:
        return lane, ensure_venv(lane, quiet)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python3 -m tools.shipped.reference_blends", description=__doc__.split("\n")[0]
    )
    parser.add_argument(
        "--folder",
        type=pathlib.Path,
        default=FOLDER,
        help="where the JSON files are (default: reference_blends/); each STEM.json gets a STEM.blend beside it",
    )
    parser.add_argument("stems", nargs="*", default=list(STEMS), help="which files (default: all six)")
    args = parser.parse_args(argv)
    missing = [s for s in args.stems if not (args.folder / f"{s}.json").is_file()]
    if missing:
        parser.error(f"no {missing[0]}.json in {args.folder}")

    lane, python = oldest_lane_python()
    if pathlib.Path(sys.prefix).resolve() != lane.venv.resolve():
        command = [str(python), "-m", "tools.shipped.reference_blends", "--folder", str(args.folder), *args.stems]
        return subprocess.run(command, cwd=REPO).returncode

    from ellimann_addon.core.mannequin.model import Mannequin

    write_blends({s: Mannequin.load(args.folder / f"{s}.json") for s in args.stems}, args.folder)
    import bpy

    print(f"{len(args.stems)} .blend files written by Blender {bpy.app.version_string} in {args.folder}")
    return 0


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    teardown.exit_with(main())
