"""What Blender prints, kept out of ElliMann's own output on the command line and in ``make bench``.

Blender prints from C straight to file descriptors 1 and 2 (``Info: Saved copy as …``, ``EGL Error …``,
the OBJ exporter's ``Writing to …`` with the temporary path), and its glTF exporter logs through a
``logging.StreamHandler`` it opens on ``sys.stdout`` for every export. Two pieces keep that apart:

- :func:`program` wraps a whole command: fds 1 and 2 go to a temporary log file (or, with ``show``,
  fd 1 goes to fd 2, so stdout stays machine-readable), while ``sys.stdout`` and ``sys.stderr``
  keep writing to the original stdout and stderr, so what ElliMann prints still shows;
- :func:`blender_output` wraps each Blender call: inside a program it points ``sys.stdout`` and
  ``sys.stderr`` at the same log for the call, so Python-level output of Blender goes there too;
  if the call fails, what it printed is added to the exception as a note (shown with a traceback).
  Outside a program (the add-on in Blender, scripts) it sends all Blender prints to stderr, as before.

No bpy here: the CLI uses it before Blender is loaded.
"""

import contextlib
import ctypes
import gc
import os
import sys
import tempfile

_program = None  # the running _Program, if any


class _Program:
    def __init__(self, show):
        self.show = show
        self.log = None if show else tempfile.TemporaryFile(prefix="ellimann-blender-")
        self.saved = {}
        self.streams = {}

    def start(self):
        _flush()
        target = os.dup(2) if self.show else os.dup(self.log.fileno())
        try:
            self.sink = _text(target, sys.__stderr__)  # where Blender's Python output goes
            for fd, name in ((1, "stdout"), (2, "stderr")):
                if fd == 2 and self.show:
                    continue  # stderr stays where it is
                self.saved[fd] = os.dup(fd)
                stream = getattr(sys, name)
                self.streams[name] = stream
                if _uses_fd(stream, fd):  # ElliMann's own prints: to the original fd
                    setattr(sys, name, _text(os.dup(self.saved[fd]), stream))
                os.dup2(self.sink.fileno(), fd)
        except BaseException:
            self.stop()
            raise

    def stop(self):
        _flush()
        for name, stream in self.streams.items():
            current = getattr(sys, name)
            if current is not stream:
                with contextlib.suppress(OSError, ValueError):
                    current.close()
                setattr(sys, name, stream)
        for fd, saved in self.saved.items():
            os.dup2(saved, fd)
            os.close(saved)
        self.saved.clear()
        self.streams.clear()
        if getattr(self, "sink", None) is not None:
            self.sink.close()
            self.sink = None

    def since(self, offset):
        """What Blender printed into the log from ``offset`` on ("" with ``show``: it is on stderr already)."""
        if self.log is None:
            return ""
        end = self.offset()
        if end <= offset:
            return ""
        fd = self.log.fileno()  # shares its offset with fds 1 and 2: read, then put it back at the end
        os.lseek(fd, offset, os.SEEK_SET)
        try:
            data = os.read(fd, end - offset)
        finally:
            os.lseek(fd, end, os.SEEK_SET)
        return data.decode("utf-8", "replace")

    def offset(self):
        if self.log is None:
            return 0
        _flush()
        self.sink.flush()
        return os.lseek(self.log.fileno(), 0, os.SEEK_CUR)


@contextlib.contextmanager
def program(show=False):
    """Run a command with Blender's output captured (``show``: sent to stderr instead of stdout).

    Nested calls are one program. What Blender printed is dropped at the end, unless the block
    ends with an exception other than ElliMann's one-line errors, when it is written to stderr.
    """
    global _program
    if _program is not None:
        yield _program
        return
    running = _Program(show)
    running.start()
    _program = running
    try:
        yield running
    except BaseException as error:
        if not show and not isinstance(error, (KeyboardInterrupt, SystemExit)) and not _explained(error):
            text = running.since(0)
            running.stop()
            if text:
                sys.stderr.write(text if text.endswith("\n") else text + "\n")
                sys.stderr.flush()
        raise
    finally:
        _program = None
        running.stop()
        if running.log is not None:
            running.log.close()


def _explained(error):
    from ...core.errors import ElliMannError

    return isinstance(error, (ElliMannError, OSError))


@contextlib.contextmanager
def blender_output():
    """Around a Blender call: its output goes to the program's log (or stderr); see the module docstring."""
    running = _program
    if running is None:
        with _stdout_to_stderr():
            yield
        return
    saved = sys.stdout, sys.stderr
    start = running.offset()
    sys.stdout = sys.stderr = running.sink
    try:
        yield
    except BaseException as error:
        # A failed Python exporter's frames (and the file it had open: Blender 5.3's glTF exporter on a
        # full disk) stay alive in sys.last_* where Blender printed its error; freed here, their
        # "Exception ignored" lines go to Blender's output, not after ElliMann's one line.
        for name in ("last_exc", "last_type", "last_value", "last_traceback"):
            if hasattr(sys, name):
                delattr(sys, name)
        gc.collect()
        sys.stdout, sys.stderr = saved
        text = running.since(start).strip()
        if text and hasattr(error, "add_note"):
            error.add_note(f"Blender printed:\n{text}")
        raise
    finally:
        running.sink.flush()
        sys.stdout, sys.stderr = saved


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send what Blender prints to stderr, so stdout stays machine-readable (C prints and sys.stdout)."""
    _flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        _flush()
        os.dup2(saved, 1)
        os.close(saved)


def _uses_fd(stream, fd):
    try:
        return stream.fileno() == fd
    except (AttributeError, OSError, ValueError):  # pytest's capsys, StringIO: they do not write to the fd
        return False


def _text(fd, like):
    """A text stream on ``fd``, encoded and buffered like the stream ``like``."""
    return open(
        fd,
        "w",
        buffering=1 if getattr(like, "line_buffering", True) else -1,
        encoding=getattr(like, "encoding", None) or "utf-8",
        errors=getattr(like, "errors", None) or "backslashreplace",
    )


def _flush():
    """Flush Python's streams and C's stdio buffers, so nothing lands on the wrong side of a dup2."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    if _libc is not None:
        with contextlib.suppress(Exception):
            _libc.fflush(None)


def _load_libc():
    if os.name != "posix":
        return None
    try:
        return ctypes.CDLL(None)
    except OSError:
        return None


_libc = _load_libc()
