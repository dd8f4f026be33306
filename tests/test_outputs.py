"""outputs.results_only_on_stdout: descriptor 1 (OMPL's std::cout) goes to stderr, Python's
standard output to the real one, and both are put back (issue 32, item 3)."""

from __future__ import annotations

import os
import subprocess
import sys

from rrtpso_ompl.outputs import results_only_on_stdout


def test_descriptor_one_goes_to_stderr_and_results_to_stdout(capfd):
    print("before", flush=True)
    with results_only_on_stdout():
        os.write(1, b"what C++ writes to std::cout\n")
        print("the result")
    os.write(1, b"after\n")
    out, err = capfd.readouterr()
    assert out == "before\nthe result\nafter\n"
    assert err == "what C++ writes to std::cout\n"


def test_children_started_in_the_block_write_descriptor_one_to_stderr(capfd):
    with results_only_on_stdout():
        subprocess.run([sys.executable, "-c", "print('a worker talks')"], check=True)
        print("the rows")
    out, err = capfd.readouterr()
    assert out == "the rows\n" and err == "a worker talks\n"


def test_a_reader_that_went_away_is_silenced_on_the_results_descriptor():
    """silence_stdout points the descriptor the results go to at the null device; descriptor 1
    keeps going to stderr until the block ends."""
    code = (
        "import os, sys\n"
        "from rrtpso_ompl.outputs import results_only_on_stdout, silence_stdout\n"
        "with results_only_on_stdout():\n"
        "    silence_stdout()\n"
        "    print('dropped')\n"
        "    os.write(1, b'still on stderr\\n')\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == "still on stderr\n"


def test_nothing_changes_for_a_stdout_that_is_not_descriptor_one(capsys):
    """A caller's own sys.stdout (pytest's capture) stays, and receives what Python prints."""
    before = sys.stdout
    with results_only_on_stdout():
        assert sys.stdout is before
        print("captured")
    assert sys.stdout is before and capsys.readouterr().out == "captured\n"
