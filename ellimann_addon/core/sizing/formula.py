"""Seamly2D / Valentina measurement formulas, evaluated safely (a parser of its own: nothing is ever ``eval``-ed).

An individual measurement file's value may be a number or a formula of other measurements of the same file, as
the tools' own expression parser reads it (docs/formats/measurement_files.md):
- numbers (``12``, ``1.5``, ``.5``, ``2e1``), names of measurements (``height``, ``bust_circ``, a custom one
  ``@my_name``), the constants ``_pi`` and ``_e``;
- ``+ - * /``, ``^`` (power, right to left), unary ``-`` and ``+`` (``-2^2`` is -4, as the tools read it),
  parentheses, the comparisons ``< > <= >= == !=``, ``&&``, ``||`` and ``cond ? a : b``;
- the functions the tools define, arguments separated by ``;``: sin cos tan asin acos atan atan2 (radians), sinD
  cosD tanD asinD acosD atanD (degrees), sinh cosh tanh asinh acosh atanh, log2 log10 log (base 10) ln exp sqrt
  sign rint abs fmod, sum avg min max (any count), degTorad radTodeg.

:func:`evaluate_all` evaluates every measurement of a file, each reference resolved once; a reference to a name the
file does not hold, a circular one, a syntax error or a value no number has (a square root of -1, a division by 0)
is refused in one line naming the measurement.
"""

import math
import re

from ..errors import ElliMannError


class FormulaError(ElliMannError):
    """A formula that cannot be evaluated: ``name`` is the measurement it belongs to."""

    def __init__(self, name, message):
        self.name = name
        super().__init__(f"{name}: {message}")


_TOKEN = re.compile(
    r"\s*(?:"
    r"(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<name>@?[^\W\d]\w*)"
    r"|(?P<op><=|>=|!=|==|&&|\|\||[-+*/^()<>?:;])"
    r")"
)


def _degrees(function):
    return lambda x: function(math.radians(x))


def _inverse_degrees(function):
    return lambda x: math.degrees(function(x))


def _sign(x):
    return float((x > 0) - (x < 0))


def _rint(x):
    return float(round(x))  # half to even, as C's rint in its default rounding mode


def _many(function):
    def apply(*args):
        if not args:
            raise ValueError("needs at least one argument")
        return function(args)

    return apply


FUNCTIONS = {
    "sin": (math.sin, 1),
    "cos": (math.cos, 1),
    "tan": (math.tan, 1),
    "asin": (math.asin, 1),
    "acos": (math.acos, 1),
    "atan": (math.atan, 1),
    "atan2": (math.atan2, 2),
    "sinD": (_degrees(math.sin), 1),
    "cosD": (_degrees(math.cos), 1),
    "tanD": (_degrees(math.tan), 1),
    "asinD": (_inverse_degrees(math.asin), 1),
    "acosD": (_inverse_degrees(math.acos), 1),
    "atanD": (_inverse_degrees(math.atan), 1),
    "sinh": (math.sinh, 1),
    "cosh": (math.cosh, 1),
    "tanh": (math.tanh, 1),
    "asinh": (math.asinh, 1),
    "acosh": (math.acosh, 1),
    "atanh": (math.atanh, 1),
    "log2": (math.log2, 1),
    "log10": (math.log10, 1),
    "log": (math.log10, 1),
    "ln": (math.log, 1),
    "exp": (math.exp, 1),
    "sqrt": (math.sqrt, 1),
    "sign": (_sign, 1),
    "rint": (_rint, 1),
    "abs": (abs, 1),
    "fmod": (math.fmod, 2),
    "degTorad": (math.radians, 1),
    "radTodeg": (math.degrees, 1),
    "sum": (_many(math.fsum), None),
    "avg": (_many(lambda a: math.fsum(a) / len(a)), None),
    "min": (_many(min), None),
    "max": (_many(max), None),
}
CONSTANTS = {"_pi": math.pi, "_e": math.e}
MAX_LENGTH = 2_000  # characters of one formula (a real one is a line)
MAX_TOKENS = 400  # numbers, names and operators of one formula (so its tree is never deeper than this)
MAX_DEPTH = 200  # nested parentheses and unary signs

_BINARY = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a / b,
    "^": lambda a, b: a**b,
    "<": lambda a, b: float(a < b),
    ">": lambda a, b: float(a > b),
    "<=": lambda a, b: float(a <= b),
    ">=": lambda a, b: float(a >= b),
    "==": lambda a, b: float(a == b),
    "!=": lambda a, b: float(a != b),
    "&&": lambda a, b: float(bool(a) and bool(b)),
    "||": lambda a, b: float(bool(a) or bool(b)),
}
_LEVELS = (("||",), ("&&",), ("<", ">", "<=", ">=", "==", "!="), ("+", "-"), ("*", "/"))


def tokens(text):
    """The tokens of a formula: [(kind, text)] with kind number, name or op; ValueError at the first character
    that is none."""
    found, at = [], 0
    text = text.rstrip()
    while at < len(text):
        match = _TOKEN.match(text, at)
        if not match or match.end() == at:
            raise ValueError(f"unexpected {text[at:].lstrip()[:12]!r}")
        kind = match.lastgroup
        found.append((kind, match.group(kind)))
        at = match.end()
    return found


class _Parser:
    """Recursive descent over the tokens into a tree of tuples: ("num", v), ("var", name), ("call", f, [args]),
    ("neg", x), ("bin", op, a, b), ("if", c, a, b)."""

    def __init__(self, items):
        self.items, self.at, self.depth = items, 0, 0

    def peek(self):
        return self.items[self.at][1] if self.at < len(self.items) else None

    def take(self, expected=None):
        if self.at >= len(self.items):
            raise ValueError(f"ends early (expected {expected!r})" if expected else "ends early")
        kind, text = self.items[self.at]
        if expected is not None and text != expected:
            raise ValueError(f"expected {expected!r}, found {text!r}")
        self.at += 1
        return kind, text

    def parse(self):
        if not self.items:
            raise ValueError("is empty")
        tree = self.ternary()
        if self.at != len(self.items):
            raise ValueError(f"unexpected {self.items[self.at][1]!r}")
        return tree

    def nested(self, parse):
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ValueError(f"is nested more than {MAX_DEPTH} deep")
        try:
            return parse()
        finally:
            self.depth -= 1

    def ternary(self):
        condition = self.binary(0)
        if self.peek() != "?":
            return condition
        self.take("?")
        yes = self.nested(self.ternary)
        self.take(":")
        return ("if", condition, yes, self.nested(self.ternary))

    def binary(self, level):
        if level == len(_LEVELS):
            return self.unary()
        left = self.binary(level + 1)
        while self.peek() in _LEVELS[level]:
            _, op = self.take()
            left = ("bin", op, left, self.binary(level + 1))
        return left

    def unary(self):
        if self.peek() in ("-", "+"):
            _, op = self.take()
            operand = self.nested(self.unary)
            return ("neg", operand) if op == "-" else operand
        return self.power()

    def power(self):
        base = self.atom()
        if self.peek() == "^":
            self.take("^")
            return ("bin", "^", base, self.nested(self.unary))  # right to left: 2^3^2 = 2^9
        return base

    def atom(self):
        kind, text = self.take()
        if kind == "number":
            return ("num", float(text))
        if kind == "name":
            if self.peek() == "(":
                if text not in FUNCTIONS:
                    raise ValueError(f"{text}() is not a function of the format ({', '.join(sorted(FUNCTIONS))})")
                self.take("(")
                args = [self.nested(self.ternary)]
                while self.peek() == ";":
                    self.take(";")
                    args.append(self.nested(self.ternary))
                self.take(")")
                count = FUNCTIONS[text][1]
                if count is not None and len(args) != count:
                    raise ValueError(f"{text}() takes {count} argument{'s' if count > 1 else ''}, got {len(args)}")
                return ("call", text, args)
            return ("num", CONSTANTS[text]) if text in CONSTANTS else ("var", text)
        if text == "(":
            inner = self.nested(self.ternary)
            self.take(")")
            return inner
        raise ValueError(f"unexpected {text!r}")


def parse(text):
    """A formula's tree (see :class:`_Parser`); ValueError saying what is wrong."""
    if not isinstance(text, str):
        raise ValueError(f"must be a text, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ValueError(f"is longer than {MAX_LENGTH:,} characters")
    items = tokens(text)
    if len(items) > MAX_TOKENS:
        raise ValueError(f"has more than {MAX_TOKENS} numbers, names and operators")
    return _Parser(items).parse()


def references(tree):
    """The measurement names a parsed formula refers to, in order of first use."""
    found = []
    stack = [tree]
    while stack:
        node = stack.pop()
        if node[0] == "var" and node[1] not in found:
            found.append(node[1])
        elif node[0] == "call":
            stack.extend(reversed(node[2]))
        elif node[0] == "neg":
            stack.append(node[1])
        elif node[0] in ("bin", "if"):
            stack.extend(reversed(node[2:] if node[0] == "bin" else node[1:]))
    return found


def _value(node, lookup):
    kind = node[0]
    if kind == "num":
        return node[1]
    if kind == "var":
        return lookup(node[1])
    if kind == "neg":
        return -_value(node[1], lookup)
    if kind == "bin":
        return _BINARY[node[1]](_value(node[2], lookup), _value(node[3], lookup))
    if kind == "if":
        return _value(node[2], lookup) if _value(node[1], lookup) else _value(node[3], lookup)
    return FUNCTIONS[node[1]][0](*(_value(arg, lookup) for arg in node[2]))


def evaluate(text, variables=None, name="formula"):
    """The value of one formula with ``variables`` {name: number}; FormulaError naming ``name``."""
    return evaluate_all({name: text}, variables)[name]


def evaluate_all(formulas, known=None):
    """{name: value} for every measurement of ``formulas`` {name: number or formula text}, each reference resolved
    from the others (or from ``known`` {name: number}); FormulaError naming the measurement for an unknown or
    circular reference, a syntax error or a value that is not a finite number."""
    known = dict(known or {})
    trees, values = {}, {}
    for name, text in formulas.items():
        if isinstance(text, int | float) and not isinstance(text, bool):
            values[name] = float(text)
            continue
        try:
            trees[name] = parse(text)
        except ValueError as error:
            raise FormulaError(name, f"the formula {_short(text)} {error}") from None

    def compute(name):
        try:
            value = _value(trees[name], lambda ref: values[ref] if ref in values else float(known[ref]))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError) as error:
            raise FormulaError(name, f"the formula {_short(formulas[name])} has no value ({error})") from None
        if isinstance(value, complex) or not math.isfinite(value):
            raise FormulaError(name, f"the formula {_short(formulas[name])} has no finite value ({value!r})")
        values[name] = float(value)

    def resolve(start):
        """Depth first without recursion (a file may chain hundreds of measurements)."""
        path, pending = [start], [iter(references(trees[start]))]
        while path:
            ref = next(pending[-1], None)
            if ref is None:
                compute(path.pop())
                pending.pop()
            elif ref in values or ref in known:
                continue
            elif ref in path:
                loop = " -> ".join(path[path.index(ref) :] + [ref])
                raise FormulaError(path[-1], f"is circular ({loop}); give one of them a number")
            elif ref not in trees:
                owner = path[-1]
                raise FormulaError(
                    owner,
                    f"the formula {_short(formulas[owner])} refers to {ref!r}, which the file does not hold; "
                    "add that measurement or write the value as a number",
                )
            else:
                path.append(ref)
                pending.append(iter(references(trees[ref])))

    for name in formulas:
        if name not in values:
            resolve(name)
    return {name: values[name] for name in formulas}


def _short(text):
    text = str(text)
    return repr(text if len(text) <= 60 else text[:57] + "...")
