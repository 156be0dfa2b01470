"""The Synthesize panel's Live step with the preview skin on, against the same step without it, in one process.

Both runs synthesize the Average request (exact mode, cushions, the armature Synthesize builds), turn Live on and
drag He over 15 steps (150-170 cm); with Skin on the skin (preview level, 10 mm) is made by Synthesize and every
step moves it with its pieces (``features.skin.live.follow``: ``Skin.following`` and the mesh written in place). The
two runs alternate over ROUNDS rounds, so that the machine's load falls on both alike. Printed: each run's median
step (wall and this process's CPU), their ratio, the follower's own median time (inside the step), the step's budget
(``LIVE_STEP_BUDGET``), and what the settle costs (the skin made again at the preview level, bound again).

``python -m bench.bench_live_skin``
"""

import statistics
import time

import numpy as np

ROUNDS = 3
STEPS = np.linspace(150.0, 170.0, 15)
AVERAGE = {"he": 159.0, "sh": 43.0, "br": 117.0, "wa": 104.0, "hi": 117.0}


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    function()
    return (time.perf_counter() - wall) * 1e3, (time.process_time() - cpu) * 1e3


def steps(bpy, props, skin, values=STEPS):
    """[wall, CPU] ms of each slider step of one run (Skin on or off) over He ``values``."""
    props.live, props.skin = False, skin
    props.mode, props.output, props.skin_level = "EXACT", "CUSHIONS", "PREVIEW"
    for key, value in AVERAGE.items():
        setattr(props, key, value)
    bpy.ops.ellimann.synthesize_mannequin()
    props.live = True
    times = [timed(lambda value=value: setattr(props, "he", float(value))) for value in values]
    props.live = False
    return times


def run(rounds=ROUNDS, quick=False):
    """``quick``: one round of three steps (checks that it runs)."""
    import bpy

    import ellimann_addon
    from ellimann_addon.blender.features.skin import live as skin_live
    from ellimann_addon.blender.features.synthesize.live import LIVE_STEP_BUDGET

    ellimann_addon.register()
    follower_times = []
    original = skin_live.follow

    def measured(scene, target, mannequin, seconds_left):
        start = time.perf_counter()
        original(scene, target, mannequin, seconds_left)
        if scene.ellimann_synthesis.skin:
            follower_times.append((time.perf_counter() - start) * 1e3)

    from ellimann_addon.blender.features.synthesize import live

    live.remove_follower(original)
    live.add_follower(measured)
    try:
        bpy.ops.wm.read_homefile(use_empty=True)
        props = bpy.context.scene.ellimann_synthesis
        props.reference_set = "FEMALE"
        runs = {False: [], True: []}
        rounds, values = (1, STEPS[::7]) if quick else (rounds, STEPS)
        settle = []
        for _ in range(rounds):
            for skin in (False, True):
                runs[skin] += steps(bpy, props, skin, values)
                if bpy.app.timers.is_registered(skin_live._settle_timer):
                    bpy.app.timers.unregister(skin_live._settle_timer)
                if bpy.app.timers.is_registered(live._settle_timer):
                    bpy.app.timers.unregister(live._settle_timer)
                if skin:
                    props.skin = True
                    settle.append(timed(lambda: skin_live.settle_skin(bpy.context.scene)))
            bpy.ops.wm.read_homefile(use_empty=True)
            props = bpy.context.scene.ellimann_synthesis
            props.reference_set = "FEMALE"
    finally:
        live.remove_follower(measured)
        live.add_follower(original)
        ellimann_addon.unregister()
    report(runs, follower_times, settle, rounds, LIVE_STEP_BUDGET, len(values))


def report(runs, follower_times, settle, rounds, budget, count=None):
    print(
        f"Live step with cushions and the armature, {count or len(STEPS)} He steps x {rounds} rounds, runs alternating"
    )
    for column, title in ((0, "wall"), (1, "CPU (this process)")):
        without = statistics.median(pair[column] for pair in runs[False])
        with_skin = statistics.median(pair[column] for pair in runs[True])
        print(
            f"  median {title:<20} without skin {without:8.2f} ms   preview skin on {with_skin:8.2f} ms   "
            f"ratio {with_skin / without:5.2f}x"
        )
    print(f"  the skin's follower inside a step (median wall): {statistics.median(follower_times):.2f} ms")
    print(f"  the step's budget (LIVE_STEP_BUDGET): {budget * 1e3:.0f} ms")
    print(
        f"  the settle (skin made again at 10 mm, weighted, bound; median wall / CPU): "
        f"{statistics.median(s[0] for s in settle):.0f} / {statistics.median(s[1] for s in settle):.0f} ms"
    )


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    run()
    teardown.exit_with(0)
