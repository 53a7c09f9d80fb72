"""Feedback during a render: a progress bar, and Ctrl-C that keeps the passes.

The drivers wait for their kernels awake (kernel/calls.py), so the handler
below runs as soon as Ctrl-C is pressed, also during a compile or a pass."""
import signal
import sys
import threading
import time as time_


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
    """Reports passes to a callable, to a tqdm bar on stderr, or nowhere.

    The bar counts samples per pixel towards spp (fractions: a pass over part
    of the rows), or seconds towards a time budget; the pass number, the spp
    reached and the rate follow it.  The callable gets (spp reached, spp
    requested or None, samples per second).
    """

    # tqdm writes desc with ": " after it, and postfix with ", " before it.
    FORMAT = "{desc}{percentage:3.0f}%|{bar}| {elapsed}<{remaining}{postfix}"

    def __init__(self, progress, spp, time=None):
        self.callback = progress if callable(progress) else None
        self.spp, self.time = spp, time
        self.t0 = time_.perf_counter()
        self._drawn = 0.0              # when tick() last redrew the bar
        self.bar = None
        if progress is True:
            tqdm = _tqdm()
            self.bar = tqdm(total=None, desc="compiling", leave=False, dynamic_ncols=True,
                            file=sys.stderr, bar_format="{desc} ({elapsed})")

    def tick(self):
        """While compiling: redraw the bar twice a second, so that its clock
        runs (a cold compile takes 6-13 s: a frozen 00:00 looks hung)."""
        if self.bar is not None:
            now = time_.perf_counter()
            if now - self._drawn >= 0.5:
                self._drawn = now
                self.bar.refresh()

    def started(self):
        """Compiling is over: restart the bar's clock so its rate is honest."""
        if self.bar is not None:
            self.bar.set_description("render", refresh=False)
            self.bar.bar_format = self.FORMAT
            self.bar.reset(total=self.time if self.time is not None else self.spp)

    def update(self, renderer, passes):
        r = renderer
        samples = r.width * (r.height * r.spp + r.rows_done * r.band)
        rate = samples / r.seconds if r.seconds > 0 else 0.0
        if self.callback is not None:
            self.callback(r.spp, self.spp, rate)
        if self.bar is not None:
            if self.time is not None:
                done, spp = min(r.seconds, self.time), f"{r.spp} spp"
            else:
                done, spp = r.spp + r.band * r.rows_done / r.height, f"{r.spp}/{self.spp} spp"
            self.bar.set_postfix_str(f"{spp}, pass {passes}, {rate / 1e6:.2f} M samples/s",
                                     refresh=False)
            self.bar.update(done - self.bar.n)
            self.bar.refresh()

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _tqdm():
    """tqdm's notebook widget in Jupyter (when ipywidgets is there), else its
    text bar on stderr."""
    from .preview import in_notebook
    if in_notebook():
        try:
            import ipywidgets  # noqa: F401
            from tqdm.notebook import tqdm
            return tqdm
        except ImportError:
            pass
    from tqdm import tqdm
    return tqdm
