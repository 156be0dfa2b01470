"""The Synthesize panel's Live step with each kind of skin on, against the same step without one, in one process.

Every run synthesizes the Average request (exact mode, cushions, the armature Synthesize builds), turns Live on and
drags He over 15 steps (150-170 cm). With the skin over the pieces (preview level, 10 mm) every step moves it with
its pieces (``features.skin.live.follow``: ``Skin.following`` and the mesh written in place); with the body skin (the
set's bodies, the panel's default) every step writes the body model's blend for the new request (no correction
until the fields are still). The runs alternate over ROUNDS rounds, so that the machine's load falls on all alike.
Printed: each run's median step (wall and this process's CPU), its ratio to the run without a skin, the follower's
own median time (inside the step), the step's budget (``LIVE_STEP_BUDGET``), and what each settle costs (the skin
made again: the pieces' at the preview level, the exact body skin; weighted and bound again).

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


KINDS = (None, "PIECES", "BODY")  # no skin, the skin over the pieces, the body skin


def steps(bpy, props, kind, values=STEPS):
    """[wall, CPU] ms of each slider step of one run (``kind``: None for no skin) over He ``values``."""
    props.live, props.skin = False, kind is not None
    props.mode, props.output, props.skin_level = "EXACT", "CUSHIONS", "PREVIEW"
    props.skin_kind = kind or "AUTO"
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
    follower_times = {kind: [] for kind in KINDS[1:]}
    original = skin_live.follow

    def measured(scene, target, mannequin, seconds_left):
        start = time.perf_counter()
        original(scene, target, mannequin, seconds_left)
        props = scene.ellimann_synthesis
        if props.skin:
            follower_times[props.skin_kind].append((time.perf_counter() - start) * 1e3)

    from ellimann_addon.blender.features.synthesize import live

    live.remove_follower(original)
    live.add_follower(measured)
    try:
        bpy.ops.wm.read_homefile(use_empty=True)
        props = bpy.context.scene.ellimann_synthesis
        props.reference_set = "FEMALE"
        runs = {kind: [] for kind in KINDS}
        rounds, values = (1, STEPS[::7]) if quick else (rounds, STEPS)
        settle = {kind: [] for kind in KINDS[1:]}
        for _ in range(rounds):
            for kind in KINDS:
                runs[kind] += steps(bpy, props, kind, values)
                if bpy.app.timers.is_registered(skin_live._settle_timer):
                    bpy.app.timers.unregister(skin_live._settle_timer)
                if bpy.app.timers.is_registered(live._settle_timer):
                    bpy.app.timers.unregister(live._settle_timer)
                if kind is not None:
                    settle[kind].append(timed(lambda: skin_live.settle_skin(bpy.context.scene)))
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
    names = {"PIECES": "the pieces' skin (preview)", "BODY": "the body skin"}
    for column, title in ((0, "wall"), (1, "CPU (this process)")):
        without = statistics.median(pair[column] for pair in runs[None])
        line = f"  median {title:<20} without a skin {without:7.2f} ms"
        for kind in KINDS[1:]:
            on = statistics.median(pair[column] for pair in runs[kind])
            line += f"   {names[kind]} {on:7.2f} ms ({on / without:4.2f}x)"
        print(line)
    for kind in KINDS[1:]:
        follower = statistics.median(follower_times[kind])
        wall, cpu = (statistics.median(s[i] for s in settle[kind]) for i in (0, 1))
        print(
            f"  {names[kind]}: its follower inside a step (median wall) {follower:.2f} ms; the settle (made again, "
            f"weighted, bound; median wall / CPU) {wall:.0f} / {cpu:.0f} ms"
        )
    print(f"  the step's budget (LIVE_STEP_BUDGET): {budget * 1e3:.0f} ms")


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    run()
    teardown.exit_with(0)
