"""Seamly2D / Valentina measurement formulas: the operators, functions and references the tools allow, evaluated
by ElliMann's own parser (never eval), and every bad formula refused in one line naming the measurement."""

import math
import random

import pytest

from ellimann_addon.core.sizing.formula import FUNCTIONS, FormulaError, evaluate, evaluate_all, parse, references


@pytest.mark.parametrize(
    "text, expected",
    [
        ("1 + 2 * 3", 7.0),
        ("(1 + 2) * 3", 9.0),
        ("-2^2", -(2.0**2)),  # unary minus binds looser than the power, as the tools read it
        ("2^3^2", 2.0 ** (3.0**2)),  # right to left
        ("2^-1", 0.5),
        ("10 / 4 - 1", 1.5),
        ("1 < 2 && 2 <= 2", 1.0),
        ("1 > 2 || 0", 0.0),
        ("3 == 3 ? 10 : 20", 10.0),
        ("3 != 3 ? 10 : 20", 20.0),
        ("sqrt(16) + abs(-2)", 6.0),
        ("max(1; 7; 3) - min(4; 2)", 5.0),
        ("sum(1; 2; 3) / avg(2; 4)", 2.0),
        ("sinD(90) + cosD(0)", 2.0),
        ("radTodeg(_pi)", 180.0),
        ("fmod(7.5; 2)", 1.5),
        ("atan2(1; 1) * 4", math.pi),
        ("1.5e1 + .5", 15.5),
    ],
)
def test_arithmetic_as_the_tools_read_it(text, expected):
    assert evaluate(text) == pytest.approx(expected, rel=1e-12)


def test_every_function_of_the_table_is_evaluated_against_math():
    rng = random.Random(7)
    for name, (function, count) in FUNCTIONS.items():
        args = [rng.uniform(1.1, 1.9) if name == "acosh" else rng.uniform(0.1, 0.9) for _ in range(count or 3)]
        text = f"{name}({'; '.join(repr(a) for a in args)})"
        assert evaluate(text) == pytest.approx(function(*args), rel=1e-12), name


def test_references_resolve_through_chains_in_any_order():
    formulas = {"c": "b * 2", "a": "10", "b": "a + 1", "@custom": "c - a"}
    values = evaluate_all(formulas)
    assert values == {"c": 22.0, "a": 10.0, "b": 11.0, "@custom": 12.0}
    assert references(parse("a + max(b; c) * (d ? e : f)")) == ["a", "b", "c", "d", "e", "f"]


def test_a_long_chain_does_not_recurse():
    formulas = {f"m{i}": f"m{i - 1} + 1" for i in range(1, 3000)}
    formulas["m0"] = "0"
    assert evaluate_all(formulas)["m2999"] == 2999.0


@pytest.mark.parametrize(
    "formulas, words",
    [
        ({"hip_circ": "waist_circ + 20"}, ["hip_circ", "'waist_circ'", "does not hold"]),
        ({"a": "b", "b": "c", "c": "a"}, ["circular", "a -> b -> c -> a"]),
        ({"a": "a + 1"}, ["circular", "a -> a"]),
        ({"a": "sqrt(-1)"}, ["a:", "no value"]),
        ({"a": "1 / (2 - 2)"}, ["a:", "no value"]),
        ({"a": "2 +"}, ["a:", "ends early"]),
        ({"a": "(1 + 2"}, ["a:", "expected ')'"]),
        ({"a": "1 2"}, ["a:", "unexpected '2'"]),
        ({"a": "foo(1)"}, ["foo() is not a function"]),
        ({"a": "sqrt(1; 2)"}, ["sqrt() takes 1 argument"]),
        ({"a": "__import__('os').system('x')"}, ["a:", "unexpected"]),
        ({"a": "exp(1000)"}, ["a:", "no value"]),
        ({"a": "-" * 300 + "1"}, ["nested more than"]),
        ({"a": "+".join(["1"] * 300)}, ["more than 400"]),
    ],
)
def test_bad_formulas_are_refused_in_one_line(formulas, words):
    with pytest.raises(FormulaError) as caught:
        evaluate_all(formulas)
    message = str(caught.value)
    assert "\n" not in message
    for word in words:
        assert word in message
