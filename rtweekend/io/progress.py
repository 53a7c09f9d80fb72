"""Feedback during a render: a progress bar, and Ctrl-C that keeps the passes."""
import signal
import sys
import threading


class StopOnInterrupt:
    """First Ctrl-C: finish the current pass and stop.  Second: abort at once."""

    def __init__(self):
        self.requested = False
        self._previous = None

    def _handler(self, signum, frame):
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc):
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)


class Progress:
    """Reports passes to a callable, to a tqdm bar on stderr, or nowhere."""

    def __init__(self, progress, spp):
        self.callback = progress if callable(progress) else None
        self.spp = spp
        self.bar = None
        if progress is True:
            from tqdm import tqdm
            self.bar = tqdm(total=spp, unit="spp", desc="compiling", leave=False,
                            dynamic_ncols=True, file=sys.stderr)

    def started(self):
        """Compiling is over: restart the bar's clock so its rate is honest."""
        if self.bar is not None:
            self.bar.set_description("render", refresh=False)
            self.bar.reset(total=self.spp)

    def update(self, done, passes, seconds, pixels):
        rate = done * pixels / seconds if seconds > 0 else 0.0
        if self.callback is not None:
            self.callback(done, self.spp, rate)
        if self.bar is not None:
            self.bar.update(done - self.bar.n)
            self.bar.set_postfix_str(f"pass {passes}, {rate / 1e6:.2f} M samples/s")

    def close(self):
        if self.bar is not None:
            self.bar.close()
