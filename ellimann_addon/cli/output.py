"""ElliMann's printed lines: the program name and exit codes, the one-line usage error, lines made safe for
a terminal, the m_T line and the progress line."""

import contextlib
import re
import sys
import time

from ..core.errors import ElliMannError, one_line  # noqa: F401  (one_line: output.one_line)

PROG = "ellimann"
MISSED = 3  # exit code: written, but exact mode missed a requested measurement by more than its tolerance
INTERRUPTED = 130  # exit code after Ctrl-C, as shells report SIGINT


_capture = []  # how the running command starts capturing what Blender prints (cli.main), at most once


@contextlib.contextmanager
def blender_capture(start):
    """While a command runs: ``start()`` captures what Blender prints from then on (``blender_used`` calls it)."""
    _capture.append([start, False])
    try:
        yield
    finally:
        _capture.pop()


def blender_used():
    """Before the command's first Blender call: what Blender prints from then on is captured (once)."""
    if _capture and not _capture[-1][1]:
        _capture[-1][1] = True
        _capture[-1][0]()


class UsageError(ElliMannError):
    """A mistake on the command line or in an input file, reported in one line."""


_UNPRINTABLE = re.compile(r"[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069]")


def printable(text):
    """``text`` with control characters (terminal escapes, carriage returns, bidi overrides) as \\x1b, \\n…"""
    return _UNPRINTABLE.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def say(text, file=None, end="\n"):
    """Print one of ElliMann's lines (stderr unless ``file``), escaping what a terminal would act on."""
    print(printable(text), file=file or sys.stderr, end=end, flush=True)


class Progress:
    """One progress line on stderr: count, rate and time left, rewritten in place on a terminal, every ~5% in a
    log; nothing with ``quiet`` (``-q``)."""

    def __init__(self, total, command, every=None, quiet=False):
        self.total, self.count, self.start = total, 0, time.perf_counter()
        self.command, self.quiet = command, quiet
        self.stream = sys.stderr  # ElliMann's stderr, also from inside blender_output() (where sys.stderr is Blender's)
        self.tty = self.stream.isatty()
        self.every = every or max(1, total // 20)
        self.shown = 0.0  # when the line was last rewritten (a terminal gets at most ~10 a second)

    def step(self, name, count=None):
        """One more done (``name``: what), or ``count`` done so far; repeated counts are ignored."""
        if count is not None and count <= self.count:
            return
        previous = self.count
        self.count = self.count + 1 if count is None else count
        if self.quiet:
            return
        now = time.perf_counter()
        due = (
            (now - self.shown >= 0.1 or self.count == self.total)
            if self.tty
            else (self.count // self.every > previous // self.every or self.count == self.total)
        )
        if due:
            self.shown = now
            text = printable(f"{PROG} {self.command}: {self.line(now)} {name}")
            print(
                f"\r{text[:100]:<100}" if self.tty else text, end="" if self.tty else "\n", file=self.stream, flush=True
            )

    def line(self, now):
        """ "120/2000 (41.5/s, 45 s left)": count, rate and the time left at that rate."""
        elapsed = max(now - self.start, 1e-9)
        rate = self.count / elapsed
        left = (self.total - self.count) / rate if rate > 0 else 0.0
        return f"{self.count}/{self.total} ({rate:.1f}/s, {duration(left)} left)"

    def done(self):
        if self.tty and self.total and not self.quiet:
            print(file=self.stream)


def duration(seconds):
    """ "45 s", "12 min 5 s", "2 h 3 min": a time left, to the second below a minute."""
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60} min"
