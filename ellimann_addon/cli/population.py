"""``ellimann population``: N rows of measurements sampled from a survey's statistics (``core.synthesis.population``)
into a CSV that ``batch`` reads; with --synthesize DIR the mannequins too, through batch."""

import argparse
import csv
import io
import sys

from ..core.measurements import MEASUREMENTS
from ..core.synthesis.population import MAX_SAMPLES, load_population, shipped_populations
from . import arguments, batch, output, writing
from .output import PROG, UsageError


def add_parser(commands):
    population = commands.add_parser(
        "population",
        help="sample measurement rows from a survey's statistics",
        description="Sample N rows of measurements (cm) from a survey's mean and covariance (a multivariate "
        "normal; docs/population.md) into a CSV for batch: name, He, Sh, Br, Wa, Hi (and with --extras "
        "the survey's other measurements). The same --seed gives the same rows everywhere. Rows outside "
        "what a body can be are refused and counted.",
    )
    population.add_argument(
        "--stats",
        required=True,
        metavar="NAME",
        help=f"a shipped survey ({', '.join(shipped_populations())}) or a statistics .json file",
    )
    population.add_argument("--n", required=True, type=int, metavar="N", help=f"rows to sample (1 to {MAX_SAMPLES:,})")
    population.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the sampling (default 0)")
    population.add_argument("-o", "--output", required=True, metavar="PEOPLE.csv", help="the CSV to write")
    population.add_argument(
        "--extras",
        action="store_true",
        help="also write the survey's other measurements; batch then meets those it knows (neck, "
        "thigh, calf, crotch_height...) in exact mode, at seconds per mannequin instead of "
        "milliseconds",
    )
    population.add_argument(
        "--synthesize",
        metavar="DIR",
        help="also synthesize every row into DIR, as batch does (report.csv and --format)",
    )
    population.add_argument(
        "--format", default="npz", help="with --synthesize: batch's output formats (default npz, one file for all)"
    )
    population.add_argument("--dask", metavar="ADDRESS", help="with --synthesize: batch's --dask")
    arguments.add_synthesis_options(population)
    arguments.add_pose_option(population)  # with --synthesize: batch's --pose
    population.set_defaults(run=run, blender=lambda args: None)  # --synthesize: the batch's job checks its files


def run(args):
    if not args.output.lower().endswith(".csv"):
        raise UsageError(f"-o must name a .csv file, got {args.output!r}")
    population = load_population(args.stats)
    rows, accepted = population.sample(args.n, args.seed)
    refused = int((~accepted).sum())
    if refused == len(rows):
        raise UsageError(
            f"all {len(rows)} sampled rows are outside what a body can be (a value <= 0 cm or outside "
            "the plausible limits); nothing written"
        )
    if refused:
        output.say(
            f"{PROG} population: refused {refused} of {len(rows)} sampled rows outside what a body can be "
            "(a value <= 0 cm or outside the plausible limits)"
        )
    keys = list(population.keys)
    columns = range(len(keys)) if args.extras else [keys.index(key) for key in MEASUREMENTS]
    writing.write_text(args.output, population_csv([keys[c] for c in columns], rows[:, list(columns)], accepted))
    output.say(
        f"{PROG} population: wrote {len(rows) - refused} rows sampled from {population.name} (seed "
        f"{args.seed}) to {args.output}",
        file=sys.stdout,
    )
    if not args.synthesize:
        return 0
    return batch.run(
        argparse.Namespace(
            # no skin: the batch file population writes holds the pieces only
            **{
                **vars(args),
                "csv": args.output,
                "output": args.synthesize,
                "shard": None,
                "resume": False,
                "skin": False,
            }
        )
    )


def population_csv(keys, rows, accepted):
    """The CSV batch reads: name (``person-00001``… by sample number), then every key, in cm to 0.01."""
    width = max(5, len(str(len(rows))))
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["name", *keys])
    for number, (values, good) in enumerate(zip(rows, accepted), start=1):
        if good:
            writer.writerow([f"person-{number:0{width}d}", *(f"{v:.2f}" for v in values)])
    return stream.getvalue()
