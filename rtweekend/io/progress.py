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

    # tqdm writes desc with ": " after it, and postfix with ", " before it.  The
    # time left is ours (LEFT): tqdm's own, from its clock and the bar's count,
    # read hours at the start of a one-minute render (the first pass covers a
    # row per thread, a sliver of the work, in the time of a whole one).
    FORMAT = "{desc}{percentage:3.0f}%|{bar}| {elapsed}<LEFT{postfix}"

    def __init__(self, progress, spp, time=None):
        self.callback = progress if callable(progress) else None
        self.spp, self.time = spp, time
        self.t0 = time_.perf_counter()
        self.bar = None
        self._show = progress is True    # the bar appears once the passes start

    def started(self):
        """Compiling is over (Spinner said so while it lasted): the bar, its
        clock starting now, so its rate is honest."""
        if self._show:
            self.bar = _tqdm()(total=self.time if self.time is not None else self.spp,
                               desc="render: ", leave=False, dynamic_ncols=True, file=sys.stderr,
                               bar_format=self.FORMAT.replace("LEFT", "?"))

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
                done, spp = _spp_done(r), f"{r.spp}/{self.spp} spp"
            left = self.time_left(r, passes)
            self.bar.bar_format = self.FORMAT.replace(
                "LEFT", "?" if left is None else self.bar.format_interval(left))
            self.bar.set_postfix_str(f"{spp}, pass {passes}, {rate / 1e6:.2f} M samples/s",
                                     refresh=False)
            self.bar.update(done - self.bar.n)
            self.bar.refresh()

    def time_left(self, r, passes):
        """Seconds of rendering left, or None while unknown: from the rate of
        the samples rendered so far (the render's own seconds, no compile),
        once a pass beyond the first has measured it."""
        if self.time is not None:
            return max(0.0, self.time - r.seconds)
        done = _spp_done(r)
        if passes < 2 or done <= 0 or r.seconds <= 0:
            return None
        return max(0.0, self.spp - done) * r.seconds / done

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _spp_done(r):
    """Samples per pixel done, with a pass over part of the rows as its fraction."""
    return r.spp + r.band * r.rows_done / r.height


class Spinner:
    """"compiling (00:07)" on stderr while anything compiles (and after GRACE
    seconds of it, so a run whose kernels are all cached shows nothing), from
    the first compile on: reading a mesh file, packing the scene, its BVH, the
    kernels (kernel/compile_clock.py says when something compiles).

        with Spinner(enabled):
            ...                          # a render: one spinner, however nested
    """

    GRACE = 0.25         # seconds a compile runs before the spinner shows
    REDRAW = 0.5         # seconds between redraws of its clock
    _active = 0          # spinners entered and not left (the outermost draws)

    def __init__(self, enabled=True):
        self.enabled = enabled
        self._stop = threading.Event()
        self._thread = None

    def __enter__(self):
        Spinner._active += 1
        if self.enabled and Spinner._active == 1:
            self._thread = threading.Thread(target=self._run, name="rtweekend-spinner",
                                            daemon=True)
            self._thread.start()
        return self

    def __exit__(self, *exc):
        Spinner._active -= 1
        if self._thread is not None:
            self._stop.set()
            self._thread.join()

    def _run(self):
        from ..kernel import compile_clock
        bar = None
        while not self._stop.wait(0.05):
            running = compile_clock.running()
            if running is not None and running >= self.GRACE:
                if bar is None:
                    bar, drawn = _tqdm()(total=None, leave=False, dynamic_ncols=True,
                                         file=sys.stderr, bar_format="{desc}"), 0.0
                now = time_.perf_counter()
                if now - drawn >= self.REDRAW:
                    minutes, seconds = divmod(int(running), 60)
                    bar.set_description_str(f"compiling ({minutes:02d}:{seconds:02d})")
                    drawn = now
            elif bar is not None:
                bar.close()
                bar = None
        if bar is not None:
            bar.close()


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
