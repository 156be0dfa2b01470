"""Populations sampled from a survey's statistics: the sample's mean and covariance within sampling error of the
survey's, the fixed-order Cholesky against LAPACK's, the sampling against the same normal deviates through
numpy's own algebra, bad statistics files refused naming the field, implausible rows refused and counted."""

import copy
import csv
import json

import numpy as np
import pytest

from devkit import synthetic
from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.synthesis.population import (
    POPULATIONS_FOLDER,
    PopulationError,
    cholesky,
    load_population,
    population_from_dict,
)

SHIPPED = json.loads((POPULATIONS_FOLDER / "ansur2_female.json").read_text(encoding="utf-8"))


def test_sample_mean_and_covariance_are_the_surveys_within_sampling_error():
    population = load_population("ansur2_female")
    count = 20000
    rows, accepted = population.sample(count, 2026)
    assert accepted.all()  # a survey's normal stays within what a body can be
    variance = np.diag(population.covariance)
    mean_error = np.abs(rows.mean(axis=0) - population.mean) / np.sqrt(variance / count)
    assert mean_error.max() < 4.5  # 4.5 standard errors over 12 means
    sample = np.cov(rows, rowvar=False)
    # Standard error of a sample covariance of normal data: sqrt((s_ii s_jj + s_ij^2) / n).
    error = np.sqrt((np.outer(variance, variance) + population.covariance**2) / count)
    assert (np.abs(sample - population.covariance) / error).max() < 4.5


def test_cholesky_in_a_fixed_order_is_lapacks():
    covariance = load_population("ansur2_female").covariance
    factor = cholesky(covariance)
    np.testing.assert_allclose(factor, np.linalg.cholesky(covariance), rtol=0, atol=1e-12)
    np.testing.assert_allclose(factor @ factor.T, covariance, rtol=1e-13, atol=1e-12)
    assert np.all(np.triu(factor, 1) == 0.0)


def test_sampling_is_the_mean_plus_the_factor_times_pcg64_normals():
    population = load_population("ansur2_female")
    rows, _ = population.sample(500, 9)
    deviates = np.random.Generator(np.random.PCG64(9)).standard_normal((500, len(population.keys)))
    np.testing.assert_allclose(
        rows, population.mean + deviates @ np.linalg.cholesky(population.covariance).T, rtol=1e-13, atol=1e-10
    )
    again, _ = population.sample(500, 9)
    np.testing.assert_array_equal(rows, again)
    assert not np.array_equal(rows, population.sample(500, 10)[0])


def altered(change):
    data = copy.deepcopy(SHIPPED)
    change(data)
    return data


@pytest.mark.parametrize(
    "change, field",
    [
        (lambda d: d["covariance"][1].__setitem__(1, 1.0) or d.pop("std"), "not positive definite (at Sh"),
        (lambda d: d["covariance"][0].__setitem__(1, 99.0), "covariance is not symmetric"),
        (lambda d: d["mean"].__setitem__("Wa", -80.0), "mean.Wa must be > 0"),
        (lambda d: d.__setitem__("colour", "red"), "colour is not a field"),
        (lambda d: d["mean"].__setitem__("elbow", 3.0), "mean.elbow is not one of keys"),
        (lambda d: d["std"].__setitem__("He", 9.0), "std.He is 9"),
        (lambda d: d.__setitem__("keys", ["Sh", "He", *d["keys"][2:]]), "keys must start with He, Sh"),
        (lambda d: d["covariance"].pop(), "covariance must be a 12 x 12 matrix"),
        (lambda d: d.pop("citation"), "citation is missing"),
        (lambda d: d.__setitem__("units", "in"), "units must be 'cm'"),
    ],
)
def test_bad_statistics_are_refused_naming_the_field(change, field):
    with pytest.raises(PopulationError, match="x") as caught:
        population_from_dict(altered(change), "x")
    assert field in str(caught.value)


def write_stats(tmp_path, data):
    path = tmp_path / "stats.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return str(path)


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--n", "0"], ["from 1 to 1,000,000", "got 0"]),
        (["--n", "5000000"], ["from 1 to 1,000,000"]),
        (["--n", "5", "--seed", "-1"], ["seed must be a non-negative integer"]),
        (["--n", "5", "--stats", "nowhere"], ["no shipped statistics named 'nowhere'"]),
    ],
)
def test_bad_command_lines_write_nothing(tmp_path, capsys, argv, words):
    stats = [] if "--stats" in argv else ["--stats", "ansur2_female"]
    code, _, err = run(["population", *stats, *argv, "-o", str(tmp_path / "p.csv")], capsys)
    assert_one_line_error(code, err, *words)
    assert not list(tmp_path.iterdir())


def test_a_non_positive_definite_file_is_one_line_and_nothing_written(tmp_path, capsys):
    stats = write_stats(tmp_path, altered(lambda d: d["covariance"][2].__setitem__(2, 0.5) or d.pop("std")))
    code, _, err = run(["population", "--stats", stats, "--n", "5", "-o", str(tmp_path / "p.csv")], capsys)
    assert_one_line_error(code, err, "not positive definite", "Br")
    assert not (tmp_path / "p.csv").exists()


def test_rows_outside_a_body_are_refused_and_counted(tmp_path, capsys):
    def short(data):  # a population around the He limit of 50 cm: about half its rows are below it
        data["mean"]["He"] = 50.0

    stats = write_stats(tmp_path, altered(short))
    out = tmp_path / "p.csv"
    code, stdout, err = run(["population", "--stats", stats, "--n", "400", "--seed", "3", "-o", str(out)], capsys)
    assert code == 0, err
    refused = int(err.split("refused ")[1].split(" of ")[0])
    rows = list(csv.DictReader(out.open(encoding="utf-8")))
    assert 100 < refused < 300 and len(rows) == 400 - refused
    assert all(float(row["He"]) >= 50.0 for row in rows)
    names = [int(row["name"].split("-")[1]) for row in rows]  # refused rows leave gaps: numbers are the samples'
    assert names == sorted(names) and names[-1] <= 400 and len(set(names)) == len(names)


def test_synthesize_writes_the_batch(tmp_path, capsys):
    references = str(synthetic.write_reference_folder(tmp_path / "rm"))
    code, stdout, err = run(
        [
            "population",
            "--stats",
            "ansur2_female",
            "--n",
            "12",
            "--seed",
            "5",
            "-q",
            "-o",
            str(tmp_path / "p.csv"),
            "--synthesize",
            str(tmp_path / "out"),
            "--references",
            references,
        ],
        capsys,
    )
    assert code in (0, 3), err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["mannequins.npz", "report.csv"]
    report = list(csv.DictReader((tmp_path / "out" / "report.csv").open(encoding="utf-8")))
    people = list(csv.DictReader((tmp_path / "p.csv").open(encoding="utf-8")))
    assert [r["name"] for r in report] == [p["name"] for p in people]
    assert [r["He"] for r in report] == [f"{float(p['He']):g}" for p in people]


def test_the_csv_holds_the_five_unless_extras_are_asked(tmp_path, capsys):
    """The survey's other measurements (neck, thigh, ...) would make batch meet them in exact mode, seconds per
    mannequin: they are written only with --extras, on the same sampled rows."""
    five, every = tmp_path / "five.csv", tmp_path / "every.csv"
    for path, more in ((five, []), (every, ["--extras"])):
        code, _, err = run(
            ["population", "--stats", "ansur2_female", "--n", "20", "--seed", "3", "-q", "-o", str(path), *more], capsys
        )
        assert code == 0, err
    short = list(csv.DictReader(five.open(encoding="utf-8")))
    full = list(csv.DictReader(every.open(encoding="utf-8")))
    assert list(short[0]) == ["name", "He", "Sh", "Br", "Wa", "Hi"]
    assert len(full[0]) > 6 and "neck" in full[0]
    assert [{k: r[k] for k in short[0]} for r in full] == short
