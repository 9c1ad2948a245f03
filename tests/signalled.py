"""Child processes that a test sends a signal to start with that signal at its default disposition.

A command started from a background job (``cmd &`` in a non-interactive shell,
``nohup``, cron, a CI wrapper) inherits "ignore SIGINT" (and SIGQUIT), and
every process it starts inherits it in turn: a signal ignored stays ignored
across fork and exec. CPython installs its KeyboardInterrupt handler only over
the default disposition, so a ``python -m ballcage`` started by pytest there
ignores the SIGINT a test sends it and runs on (issue 24, item 10).

`python_command` starts the child through a short ``python -c`` bootstrap that
sets SIGINT and SIGTERM to their default disposition and then execs the real
command line; a default disposition survives exec, so the child's interpreter
installs its own SIGINT handler as it does when started from a terminal.
(Not ``Popen(preexec_fn=...)``: that runs Python between fork and exec and may
deadlock when the test process has other threads, as pyarrow's and the
engine's thread pools are.)

Every test that signals a child starts it with `python_command`.
"""

from __future__ import annotations

import signal
import sys

__all__ = ["DEFAULT_DISPOSITION", "python_command"]

#: The signals the tests send that a parent can leave ignored (SIGKILL cannot be ignored).
DEFAULT_DISPOSITION: tuple[signal.Signals, ...] = (signal.SIGINT, signal.SIGTERM)

_BOOTSTRAP = (
    "import os, signal, sys\n"
    f"for number in {tuple(int(s) for s in DEFAULT_DISPOSITION)}:\n"
    "    signal.signal(number, signal.SIG_DFL)\n"
    "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])\n"
)


def python_command(*args: str) -> list[str]:
    """The command line that runs ``python ARGS`` with the `DEFAULT_DISPOSITION` signals at their default.

    ``python_command("-m", "ballcage", "run", ...)``: pass it to `subprocess.Popen`.
    """
    return [sys.executable, "-c", _BOOTSTRAP, *args]
