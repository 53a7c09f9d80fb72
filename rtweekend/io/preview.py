"""A live preview in a Jupyter notebook: one image that updates in place.

render(..., preview=True) shows the result so far -- the tone-mapped image
with its caption (RenderResult._repr_html_): spp, seconds, samples/s and the
standard error -- as one display (IPython's display id), updated after passes
at most every MIN_INTERVAL seconds and once at the end, so that an interrupted
kernel (Ctrl-C: the render returns what it has) leaves its last image shown.
The preview only reads the film: the image is the same bits with or without
it.
"""
import sys
import time

from ..errors import SceneError

# Seconds between updates: the passes wait for an update (the result and its
# PNG), so the interval bounds what previews cost (benchmarks/preview.py;
# benchmarks/results/measurements.md).
MIN_INTERVAL = 0.75


def in_notebook():
    """Is this code running in a Jupyter kernel (not a terminal IPython)?"""
    if "IPython" not in sys.modules:     # a kernel has it loaded; importing it takes
        return False                     # a second on a busy machine (the spinner waits)
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def require():
    """SceneError (one line) unless a notebook can show the preview."""
    if not in_notebook():
        raise SceneError("render: preview: True shows the image as it renders in a Jupyter "
                         "notebook, and this is not one (the progress bar works anywhere)")


class Preview:
    """What a live preview does with a render: update() after passes, at most
    every `interval` seconds (always when final), with the result so far;
    show(result) draws it (the subclass's); close() at the end."""

    interval = MIN_INTERVAL
    last = 0.0                       # when update() last drew

    def update(self, renderer, final=False):
        now = time.perf_counter()
        if final or now - self.last >= self.interval:
            self.show(renderer.result(denoise=False))
            self.last = now

    def show(self, result):
        raise NotImplementedError

    def close(self):
        pass


class NotebookPreview(Preview):
    """One display in the notebook, updated in place."""

    def __init__(self, first=None):
        """Display `first` (a result), or a line saying the render is on."""
        from IPython.display import display
        if first is None:
            self.handle = display({"text/plain": "rendering..."}, raw=True, display_id=True)
        else:
            self.handle = display(first, display_id=True)
            self.last = time.perf_counter()

    def show(self, result):
        self.handle.update(result)
