"""chatter: what Blender prints (to fds 1 and 2 from C, to sys.stdout from Python) kept off ElliMann's lines."""

import os
import sys

import pytest

from ellimann_addon.blender.services.chatter import blender_output, program
from ellimann_addon.core.errors import ElliMannError


def blender_prints(tag):
    """Output as Blender makes it: C writes to the file descriptors, the glTF exporter logs to sys.stdout."""
    os.write(1, f"C stdout {tag}\n".encode())
    os.write(2, f"C stderr {tag}\n".encode())
    print(f"Python {tag}")


def test_a_program_shows_its_own_lines_and_drops_blenders(capfd):
    with program():
        print("ellimann: own stdout")
        print("ellimann: own stderr", file=sys.stderr)
        os.write(1, b"C outside a Blender call\n")
        with blender_output():
            blender_prints("inside")
            print("inside a Blender call sys.stderr is Blender's", file=sys.stderr)
        print("ellimann: after")
    out, err = capfd.readouterr()
    assert out == "ellimann: own stdout\nellimann: after\n"
    assert err == "ellimann: own stderr\n"
    print("restored")
    os.write(1, b"fd restored\n")
    assert capfd.readouterr().out == "restored\nfd restored\n"


def test_show_sends_blenders_output_to_stderr_and_keeps_stdout_clean(capfd):
    with program(show=True):
        print("ellimann: result")
        with blender_output():
            blender_prints("shown")
    out, err = capfd.readouterr()
    assert out == "ellimann: result\n"
    assert "C stdout shown" in err and "C stderr shown" in err and "Python shown" in err


def test_a_failing_blender_call_keeps_what_it_printed_as_a_note(capfd):
    with pytest.raises(ZeroDivisionError) as raised, program():
        with blender_output():
            blender_prints("before")
        with blender_output():
            blender_prints("failing")
            1 / 0  # noqa: B018
    note = "\n".join(raised.value.__notes__)
    assert "C stdout failing" in note and "Python failing" in note and "before" not in note
    _, err = capfd.readouterr()  # an unexpected failure shows all of Blender's output, for the traceback
    assert "C stdout before" in err and "C stderr failing" in err


def test_an_explained_failure_stays_one_line(capfd):
    with pytest.raises(ElliMannError), program():
        with blender_output():
            blender_prints("chatter")
        raise ElliMannError("one line")
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_outside_a_program_blender_output_goes_to_stderr(capfd):
    """The add-on in Blender and scripts: nothing captured, stdout kept machine-readable as before."""
    with blender_output():
        blender_prints("script")
    out, err = capfd.readouterr()
    assert out == "" and "C stdout script" in err and "Python script" in err


def test_nested_programs_are_one(capfd):
    with program() as outer, program() as inner:
        assert inner is outer
        with blender_output():
            blender_prints("nested")
    assert capfd.readouterr() == ("", "")
