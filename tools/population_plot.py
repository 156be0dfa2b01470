"""Dev tool (not shipped; matplotlib, never inside Blender): a population's picture for the docs.

Per measurement: the histogram of the requested (sampled) values, the measured m_T of the synthesized
mannequins over it, the survey's normal; below, the relative error of m_T against the request.

    python -m tools.population_plot PEOPLE.csv REPORT.csv -o PNG [--stats ansur2_female]
"""

import argparse
import csv
import math

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ellimann_addon.core.constants import MEASUREMENTS  # noqa: E402
from ellimann_addon.core.population import load_population  # noqa: E402

NAMES = {"He": "height", "Sh": "shoulder width", "Br": "bust", "Wa": "waist", "Hi": "hips"}


def read_report(path):
    """Rows of a batch report that were written: (requested (B, 5), measured (B, 5)) in cm."""
    with open(path, newline="", encoding="utf-8") as stream:
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
        top.hist(measured[:, index], bins=bins, density=True, histtype="step", color="#c0392b", linewidth=1.6,
                 label="measured m_T")
        x = np.linspace(bins[0], bins[-1], 200)
        top.plot(x, np.exp(-0.5 * ((x - mean) / std) ** 2) / (std * math.sqrt(2 * math.pi)), color="black",
                 linewidth=1.0, linestyle="--", label=f"survey N({mean:.1f}, {std:.1f}²)")
        top.set_title(f"{key} ({NAMES[key]}), cm")
        top.set_yticks([])
        bottom.hist(error[:, index], bins=np.linspace(-0.0012, 0.0012, 25), color="#7f8c8d")
        bottom.axvline(-0.001, color="#c0392b", linewidth=0.8)
        bottom.axvline(0.001, color="#c0392b", linewidth=0.8)
        bottom.set_xlabel("m_T - request, % (tolerance ±0.001)")
        bottom.set_yticks([])
        bottom.ticklabel_format(axis="x", style="plain")
    axes[0, 0].legend(loc="upper left", fontsize=8, frameon=False)
    figure.suptitle(f"{len(requested):,} of {people_count:,} bodies sampled from {population.name} "
                    f"(multivariate normal), synthesized in exact mode", fontsize=12)
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("people", help="the CSV ellimann population wrote")
    parser.add_argument("report", help="the report.csv of the batch on it")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    parser.add_argument("--stats", default="ansur2_female", help="the survey sampled (default ansur2_female)")
    args = parser.parse_args(argv)
    with open(args.people, newline="", encoding="utf-8") as stream:
        people = sum(1 for _ in csv.DictReader(stream))
    requested, measured = read_report(args.report)
    plot(people, requested, measured, load_population(args.stats), args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
