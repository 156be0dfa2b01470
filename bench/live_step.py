"""One source tree's live step, headless (run by ``bench_live`` as a script, with PYTHONPATH=TREE): prints a JSON
object of [wall, CPU] milliseconds per case. Works on the trees ``bench_live`` compares (eb01e27's flat layout
and today's packages), so it imports only bpy, numpy and that tree's ``ellimann_addon``.

Cases (each a list of [wall ms, CPU ms]): ``ellipsoids``, ``cushions`` (a rig too where Synthesize builds one),
``cushions, no rig`` (the rig removed first; trees that rig), ``single request`` (the core's exact synthesis
of one request), ``panel request`` (the request as the live step asks the core for it).
"""

import json
import os
import sys
import tempfile
import time

import numpy as np

STEPS = np.linspace(150.0, 170.0, 3 if "--quick" in sys.argv else 15)  # He, cm: 15 slider steps (--quick: 3); the
# other four stay the Average RM's
AVERAGE = {"sh": 43.0, "br": 117.0, "wa": 104.0, "hi": 117.0}


def timed(function):
    """[wall ms, CPU ms of this process] of one call (the CPU time is less at the mercy of a loaded machine)."""
    wall, cpu = time.perf_counter(), time.process_time()
    function()
    return [(time.perf_counter() - wall) * 1e3, (time.process_time() - cpu) * 1e3]


def slider(bpy, props, output, without_rig=False):
    """Synthesize at He 159 (exact mode), turn Live on, then drag He over STEPS: [wall, CPU] ms per step."""
    props.live = False
    props.mode, props.output, props.he = "EXACT", output, 159.0
    for key, value in AVERAGE.items():
        setattr(props, key, value)
    bpy.ops.ellimann.synthesize_mannequin()
    if without_rig:
        from ellimann_addon.blender.services.rig import remove_rig

        if not remove_rig(props.target):
            return None
    props.live = True  # one update: the mannequin as it is
    times = [timed(lambda value=value: setattr(props, "he", float(value))) for value in STEPS]
    props.live = False
    return times


def requests_of(props):
    """(the core's one-request synthesis, the panel's request) of this tree, as functions of He."""
    try:
        from ellimann_addon.blender.features.synthesize import request as panel
        from ellimann_addon.core.synthesis.shipped import named_reference_set
        from ellimann_addon.core.synthesis.synthesize import synthesize
    except ImportError:  # eb01e27's layout
        from ellimann_addon.blender import synthesize as panel_module
        from ellimann_addon.core.synthesis import cached_reference_set, synthesize

        reference = cached_reference_set(None)

        def core(he):
            return synthesize(reference, dict(He=he, Sh=43.0, Br=117.0, Wa=104.0, Hi=117.0), "exact")

        return core, lambda: panel_module._synthesize(props)
    reference = named_reference_set("female")

    def core(he):
        return synthesize(reference, dict(He=he, Sh=43.0, Br=117.0, Wa=104.0, Hi=117.0))

    extra_aware = "measure_extra" in panel.synthesize_request.__code__.co_varnames
    return core, (lambda: panel.synthesize_request(props, measure_extra=False)) if extra_aware else (
        lambda: panel.synthesize_request(props)
    )


def main():
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-bench-live-"))
    import bpy

    import ellimann_addon

    ellimann_addon.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    props = bpy.context.scene.ellimann_synthesis
    out = {"ellipsoids": slider(bpy, props, "ELLIPSOIDS"), "cushions": slider(bpy, props, "CUSHIONS")}
    rigged = any(o.type == "ARMATURE" for o in props.target.objects)
    out["rig"] = rigged
    if rigged:
        out["cushions, no rig"] = slider(bpy, props, "CUSHIONS", without_rig=True)
    core, panel = requests_of(props)
    out["single request"] = [timed(lambda value=value: core(float(value))) for value in STEPS]
    singles = []
    for value in STEPS:
        props.he = float(value)  # Live is off: only the field changes
        singles.append(timed(panel))
    out["panel request"] = singles
    sys.stdout.write("\n" + json.dumps(out) + "\n")
    sys.stdout.flush()
    os._exit(0)  # Blender 4.x's teardown can crash the bpy module at exit; the figures are out


if __name__ == "__main__":
    main()
