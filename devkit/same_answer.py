"""The same requests answered under another BLAS kernel, thread count or CPU (tests/core/test_same_answer.py).

    python -m devkit.same_answer OUT_DIR

runs the command line in this process on a fixed set of exactness requests and writes what it made into OUT_DIR:
the female 243 grid and every 9th of the male one (exact mode, .json), the three bodies of ../shared/refmodels
with their six extra measurements (``synth``, .json), rows of a survey with its extra measurements (``batch``),
and the skin's exact mode with and without the six (``synth --skin``, the skin's .obj). Each command's
exit code goes into OUT_DIR/codes.json. The environment chooses the kernel (``OPENBLAS_CORETYPE``), the threads
(``OPENBLAS_NUM_THREADS``) and numpy's own SIMD (``NPY_DISABLE_CPU_FEATURES``): ``environment`` gives one that
behaves as an old x86-64 CPU would.
"""

import contextlib
import csv
import io
import itertools
import json
import os
import pathlib
import sys

BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
OLD_KERNEL = "Prescott"  # OpenBLAS's kernel for the first x86-64 CPUs: every x86-64 CPU runs it
# The extra measurements of three of ../shared/refmodels' bodies as measured on their meshes (tests/core/
# test_extra_refine.py): the tall one's thigh and calf once hung on the last bits of the neck's band search.
BODIES = {
    "slim": ((148.0, 31.11, 84.97, 63.0, 83.0), (27.59, 19.95, 43.85, 32.30, 67.17, 57.02)),
    "tall": ((170.99, 30.22, 83.98, 62.99, 84.01), (29.03, 19.50, 43.55, 35.17, 80.07, 64.09)),
    "heavy": ((148.64, 47.69, 144.41, 138.79, 152.08), (36.95, 26.12, 86.13, 47.40, 65.38, 55.83)),
}
SURVEY_ROWS = 3  # rows of ANSUR II with their extra measurements (seconds each)


def environment(kernel=None, threads=None, old_cpu=False, base=None):
    """A copy of ``base`` (default os.environ) with OpenBLAS's ``kernel`` (None: as ``base`` has it, "": unset, the
    library's own pick for this CPU) and ``threads`` (None: unset, the library's own choice) and, with ``old_cpu``,
    numpy's SIMD dispatch above its baseline turned off (numpy's exp, log, sin ... then take the code paths of a CPU
    without AVX2 or AVX-512, whose last bits differ)."""
    env = dict(os.environ if base is None else base)
    for name in (*BLAS_THREADS, "NPY_DISABLE_CPU_FEATURES"):
        env.pop(name, None)
    if kernel is not None:
        env.pop("OPENBLAS_CORETYPE", None)
        if kernel:
            env["OPENBLAS_CORETYPE"] = kernel
    if threads:
        for name in BLAS_THREADS:
            env[name] = str(threads)
    if old_cpu:
        dispatched = _dispatched_features()
        if dispatched:
            env["NPY_DISABLE_CPU_FEATURES"] = " ".join(dispatched)
    return env


def _dispatched_features():
    """numpy's dispatched SIMD targets this CPU has (what NPY_DISABLE_CPU_FEATURES may turn off)."""
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # numpy 1
        from numpy.core import _multiarray_umath as umath
    return [name for name in umath.__cpu_dispatch__ if umath.__cpu_features__.get(name)]


def _run(args, codes, name, out):
    """``cli.main(args)``: its exit code into ``codes``, what it printed on stdout into OUT/name.out."""
    from ellimann_addon import cli

    printed = io.StringIO()
    with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(io.StringIO()):
        codes[name] = cli.main(args)
    (out / f"{name}.out").write_text(printed.getvalue())


def _write_rows(path, header, rows):
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows(rows)


def main(out):
    from ellimann_addon.core.constants import quartile_points
    from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    pathlib.Path(out).mkdir(parents=True, exist_ok=True)
    os.chdir(out)  # every path relative: two runs' files and lines compare byte for byte
    out = pathlib.Path(".")
    codes = {}
    for set_name, step in (("female", 1), ("male", 9)):
        ranges = named_reference_set(set_name).ranges
        grid = list(itertools.product(*[quartile_points(key, ranges) for key in MEASUREMENTS]))[::step]
        _write_rows(
            out / f"{set_name}.csv", ["name", *MEASUREMENTS], [(f"g{i:03d}", *row) for i, row in enumerate(grid)]
        )
        _run(
            ["batch", str(out / f"{set_name}.csv"), "-o", str(out / set_name), "--references", set_name, "-q"],
            codes,
            set_name,
            out,
        )
    flags = ["--" + key.replace("_", "-") for key in EXTRA_MEASUREMENTS]
    for name, (five, six) in BODIES.items():
        values = [str(value) for pair in zip(("--he", "--sh", "--br", "--wa", "--hi"), five) for value in pair]
        extra = [str(value) for pair in zip(flags, six) for value in pair]
        _run(["synth", *values, *extra, "-o", str(out / f"{name}.json"), "--json", "-q"], codes, name, out)
    _run(
        ["population", "--stats", "ansur2_female", "--n", str(SURVEY_ROWS), "--extras", "-o", str(out / "survey.csv")],
        codes,
        "population",
        out,
    )
    _run(["batch", str(out / "survey.csv"), "-o", str(out / "survey"), "-q"], codes, "survey", out)
    five, six = BODIES["tall"]
    values = [str(value) for pair in zip(("--he", "--sh", "--br", "--wa", "--hi"), five) for value in pair]
    extra = [str(value) for pair in zip(flags, six) for value in pair]
    skin = [
        "--skin",
        "--json",
        "-q",
    ]  # the final level: the preview's 10 mm voxels leave the tall body's neck 1.5 mm off
    _run(["synth", *values, *skin, "--skin-level", "preview", "-o", str(out / "skin.obj")], codes, "skin", out)
    _run(["synth", *values, *extra, *skin, "-o", str(out / "skin_extra.obj")], codes, "skin_extra", out)
    (out / "codes.json").write_text(json.dumps(codes, indent=1))


if __name__ == "__main__":
    main(sys.argv[1])
