"""A subprocess whose stderr is read as it comes: the CLI tests that wait for a
pass, a compile or a message before they signal it."""
import os
import signal
import subprocess
import threading
import time


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


class Watched:
    """args in a subprocess; self.err grows with its stderr."""

    def __init__(self, args, **popen_kwargs):
        # Ctrl-C as a terminal's child gets it: pytest started as a background
        # job of a script has SIGINT ignored, which its children would inherit
        # (and keep, as a program started under nohup should).
        self.p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  preexec_fn=_default_sigint, **popen_kwargs)
        self.err = bytearray()
        self.reader = threading.Thread(target=self._pump, daemon=True)
        self.reader.start()

    def _pump(self):
        while chunk := self.p.stderr.read1(256):
            self.err.extend(chunk)

    def wait_for(self, marker, timeout=120):
        """Until `marker` (bytes) is on stderr; fails if it never comes."""
        deadline = time.monotonic() + timeout
        while (marker not in self.err and time.monotonic() < deadline
               and self.p.poll() is None):
            time.sleep(0.02)
        assert marker in self.err, self.err.decode(errors="replace")

    def interrupt(self):
        os.kill(self.p.pid, signal.SIGINT)

    def finish(self, timeout=60):
        """Wait at most `timeout` s: (status, stdout, stderr)."""
        self.p.wait(timeout=timeout)
        self.reader.join(timeout=10)
        return self.p.returncode, self.p.stdout.read().decode(), self.err.decode(
            errors="replace")
