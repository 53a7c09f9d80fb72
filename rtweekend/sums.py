"""What a render adds up per pixel and per row, and how.

Radiance and its square (for the standard error) are summed per block of
BLOCK_SPP samples before joining the image's sums, so the sums depend only on
the sample indices, never on how passes, threads or machines split the work.
"""
import numpy as np

# Histogram of sample values (mean of r, g, b) per row, for the firefly count:
# BINS_PER_OCTAVE bins per factor of 2, from 2**LOG2_LOWEST up.
BINS_PER_OCTAVE = 16
LOG2_LOWEST = -24.0
HIST_BINS = 64 * BINS_PER_OCTAVE
# Samples summed on their own before joining the image's sums (see render_pass).
BLOCK_SPP = 16


class Sums:
    """The running sums of an image, or of one block of its samples."""
    FIELDS = ("accum", "accum2", "partial", "partial2", "valid", "row_stats", "hist_n",
              "hist_e")

    def __init__(self, height, width):
        self.accum = np.zeros((height, width, 3))
        self.accum2 = np.zeros((height, width, 3))
        self.partial = np.zeros((height, width, 3))      # the unfinished block
        self.partial2 = np.zeros((height, width, 3))
        self.valid = np.zeros((height, width), dtype=np.int64)
        self.row_stats = np.zeros((height, 2), dtype=np.int64)
        self.hist_n = np.zeros((height, HIST_BINS), dtype=np.int64)
        self.hist_e = np.zeros((height, HIST_BINS))

    def add(self, other):
        """Merge the sums of the next block(s): with the blocks merged in order
        the image is bit-identical to rendering them here, in one process."""
        for name in self.FIELDS:
            getattr(self, name).__iadd__(getattr(other, name))
