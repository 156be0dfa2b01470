"""Dev tool (not shipped; matplotlib, never inside Blender): a population's picture for the docs.

Per measurement: the histogram of the requested (sampled) values, the measured m_T of the synthesized
mannequins over it, the survey's normal; below, the relative error of m_T against the request (full
precision from the batch's mannequins.npz when there is one, else the report's four decimals).

    python -m tools.figures.population_plot PEOPLE.csv BATCH_DIR -o PNG [--stats ansur2_female]
"""

import argparse
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ellimann_addon.core.formats.npz_bundle import read_batch_file  # noqa: E402
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.population import load_population  # noqa: E402

NAMES = {"He": "height", "Sh": "shoulder width", "Br": "bust", "Wa": "waist", "Hi": "hips"}


def read_batch(folder):
    """What a batch wrote: (requested (B, 5), measured (B, 5)) in cm, from its .npz if it wrote one."""
    archive = os.path.join(folder, "mannequins.npz")
    if os.path.isfile(archive):
        arrays = read_batch_file(archive)
        return arrays["requests_cm"], arrays["measured_cm"]
    with open(os.path.join(folder, "report.csv"), newline="", encoding="utf-8") as stream:
        rows = [row for row in csv.DictReader(stream) if row["status"] in ("ok", "missed")]
    requested = np.array([[float(row[key]) for key in MEASUREMENTS] for row in rows])
    measured = np.array([[float(row[f"{key}_measured"]) for key in MEASUREMENTS] for row in rows])
    return requested, measured


def plot(people_count, requested, measured, population, path):
    figure, axes = plt.subplots(2, len(MEASUREMENTS), figsize=(17, 6.2), gridspec_kw={"height_ratios": [3, 1.4]})
    error = 100.0 * (measured - requested) / requested
    for index, key in enumerate(MEASUREMENTS):
        top, bottom = axes[0, index], axes[1, index]
        mean, std = population.mean[index], math.sqrt(population.covariance[index, index])
        bins = np.linspace(mean - 4 * std, mean + 4 * std, 41)
        top.hist(requested[:, index], bins=bins, density=True, color="#9bb7d4", label="requested (sampled)")
        top.hist(
            measured[:, index],
            bins=bins,
            density=True,
            histtype="step",
            color="#c0392b",
            linewidth=1.6,
            label="measured m_T",
        )
        x = np.linspace(bins[0], bins[-1], 200)
        top.plot(
            x,
            np.exp(-0.5 * ((x - mean) / std) ** 2) / (std * math.sqrt(2 * math.pi)),
            color="black",
            linewidth=1.0,
            linestyle="--",
            label="the survey's normal (its mean and standard deviation)",
        )
        top.set_title(f"{key} ({NAMES[key]}), cm")
        top.set_yticks([])
        bottom.hist(error[:, index], bins=np.linspace(-0.0012, 0.0012, 25), color="#7f8c8d")
        bottom.axvline(-0.001, color="#c0392b", linewidth=0.8, label="tolerance of exact mode (±0.001 %)")
        bottom.axvline(0.001, color="#c0392b", linewidth=0.8)
        bottom.set_xticks([-0.001, 0.0, 0.001], ["-0.001", "0", "+0.001"])
        bottom.set_xlabel("(m_T - request) / request, %")
        bottom.set_yticks([])
    handles, labels = (
        sum(pair, []) for pair in zip(axes[0, 0].get_legend_handles_labels(), axes[1, 0].get_legend_handles_labels())
    )
    figure.legend(handles, labels, loc="upper right", fontsize=8, frameon=False, ncol=2)
    figure.suptitle(
        f"{len(requested):,} of {people_count:,} bodies sampled from {population.name} "
        f"(multivariate normal), synthesized in exact mode",
        fontsize=12,
    )
    figure.tight_layout(rect=(0, 0, 1, 0.93))
    figure.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("people", help="the CSV ellimann population wrote")
    parser.add_argument("batch", help="the folder of the batch on it (mannequins.npz or report.csv)")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    parser.add_argument("--stats", default="ansur2_female", help="the survey sampled (default ansur2_female)")
    args = parser.parse_args(argv)
    with open(args.people, newline="", encoding="utf-8") as stream:
        people = sum(1 for _ in csv.DictReader(stream))
    requested, measured = read_batch(args.batch)
    plot(people, requested, measured, load_population(args.stats), args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
