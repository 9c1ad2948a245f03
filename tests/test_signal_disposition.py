"""The children the tests send signals to handle them however pytest was started (issue 24, item 10).

Started from a background job (``nohup``, cron, a CI wrapper), pytest inherits
"ignore SIGINT"; a plain ``python`` child inherits it too and would run on
through the SIGINT of tests/test_faults.py, test_determinism.py and
test_cli_parquet.py. Here the test process ignores the signals itself for a
moment, as such a parent does, and compares a plain child with one started by
`signalled.python_command`.
"""

from __future__ import annotations

import signal
import subprocess
import sys

from signalled import DEFAULT_DISPOSITION, python_command

#: Prints, per signal of `DEFAULT_DISPOSITION`, the handler the child's interpreter holds at start-up.
PROBE = (
    "import signal, sys\n"
    "names = {signal.SIG_IGN: 'ignored', signal.SIG_DFL: 'default', signal.default_int_handler: 'KeyboardInterrupt'}\n"
    "print(' '.join(names.get(signal.getsignal(int(n)), 'other') for n in sys.argv[1:]))\n"
)
NUMBERS = [str(int(s)) for s in DEFAULT_DISPOSITION]


def _as_started_by_an_ignoring_parent(command: list[str]) -> list[str]:
    """The child's handlers, with `DEFAULT_DISPOSITION` ignored in this process while it starts."""
    previous = {s: signal.signal(s, signal.SIG_IGN) for s in DEFAULT_DISPOSITION}
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=60, check=True)
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    return done.stdout.split()


def test_a_plain_child_of_a_parent_that_ignores_sigint_ignores_it_too() -> None:
    """The hazard: without the bootstrap, the child ignores SIGINT and SIGTERM."""
    assert _as_started_by_an_ignoring_parent([sys.executable, "-c", PROBE, *NUMBERS]) == ["ignored", "ignored"]


def test_a_child_started_by_python_command_handles_sigint_as_from_a_terminal() -> None:
    """SIGINT raises KeyboardInterrupt (CPython's own handler) and SIGTERM is at its default."""
    handlers = _as_started_by_an_ignoring_parent(python_command("-c", PROBE, *NUMBERS))
    assert handlers == ["KeyboardInterrupt", "default"]


def test_a_child_started_by_python_command_stops_at_a_real_sigint() -> None:
    """End to end: SIGINT ends the child by KeyboardInterrupt (CPython then exits by the signal), not at its end."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        wait = "import sys, time; print('ready', flush=True); time.sleep(60); sys.exit(3)"
        proc = subprocess.Popen(python_command("-c", wait), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert proc.stdout is not None and proc.stdout.readline() == "ready\n"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGINT and "KeyboardInterrupt" in err, (proc.returncode, err)
