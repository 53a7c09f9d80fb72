"""A live preview in tev (https://github.com/Tom94/tev), as pbrt-v4's
--display-server does: the linear float image streamed over tev's IPC
protocol after passes, with the per-pixel standard error as three more
channels (stderr.R, .G, .B).

The protocol, written here rather than depended on: TCP; each packet is its
length (uint32, little endian, the 4 bytes included), a type byte, then its
fields -- strings NUL-terminated, integers int32, channel offsets and strides
int64, pixels float32.  CreateImage (4) once: grab focus, name, width,
height, the channel names; UpdateImage (6) per tile of at most TILE x TILE
pixels: grab focus, name, the channel count and names, x, y, width, height,
the channels' offsets and strides into the tile's interleaved floats, the
floats.  No tev listening, or one that goes away: one warning line, and the
render goes on unchanged (the preview only reads the film).
"""
import socket
import struct
import warnings

import numpy as np

from ..errors import SceneError, SceneWarning
from .preview import Preview

DEFAULT = ("127.0.0.1", 14158)       # tev's own default
CREATE, UPDATE = 4, 6
TILE = 128
CHANNELS = ("R", "G", "B", "stderr.R", "stderr.G", "stderr.B")
# Seconds between updates: the passes wait for one, so the interval bounds
# what it costs (benchmarks/preview.py; benchmarks/results/measurements.md).
MIN_INTERVAL = 0.5


def address(spec):
    """(host, port) of "tev", "tev://HOST:PORT" or "HOST:PORT"; SceneError if bad."""
    text = spec[len("tev://"):] if spec.startswith("tev://") else spec
    if text in ("tev", ""):
        return DEFAULT
    host, _, port = text.rpartition(":")
    try:
        number = int(port)
    except ValueError:
        number = -1
    if not host or not 0 < number < 65536:
        raise SceneError(f"render: preview: expected tev, tev://HOST:PORT or HOST:PORT, "
                         f"got {spec!r}")
    return host, number


def _string(text):
    return text.encode("utf-8") + b"\0"


def _packet(kind, body):
    return struct.pack("<Ib", 5 + len(body), kind) + body


def create_packet(name, width, height, channels=CHANNELS):
    body = struct.pack("<b", 1) + _string(name) + struct.pack("<iii", width, height,
                                                              len(channels))
    return _packet(CREATE, body + b"".join(_string(c) for c in channels))


def update_packets(name, pixels, channels=CHANNELS):
    """UpdateImage packets for an H x W x C float image, tile by tile."""
    h, w, c = pixels.shape
    for y in range(0, h, TILE):
        for x in range(0, w, TILE):
            tile = np.ascontiguousarray(pixels[y:y + TILE, x:x + TILE], dtype="<f4")
            th, tw = tile.shape[:2]
            body = (struct.pack("<b", 0) + _string(name) + struct.pack("<i", c)
                    + b"".join(_string(n) for n in channels)
                    + struct.pack("<iiii", x, y, tw, th)
                    + struct.pack(f"<{c}q", *range(c)) + struct.pack(f"<{c}q", *([c] * c))
                    + tile.tobytes())
            yield _packet(UPDATE, body)


def pixels_of(result):
    """The H x W x 6 floats a tev is sent: the image, then its standard error (0
    where it has none yet)."""
    return np.concatenate([result.image, np.where(np.isfinite(result.stderr),
                                                  result.stderr, 0.0)], axis=2)


class TevPreview(Preview):
    """The stream of one render to a tev; inert (after one warning) if none answers."""

    interval = MIN_INTERVAL

    def __init__(self, spec, name, width, height):
        self.host, self.port = address(spec)
        self.name = name
        try:
            self.sock = socket.create_connection((self.host, self.port), timeout=1.0)
            self.sock.sendall(create_packet(name, width, height))
        except OSError as e:
            self._give_up(f"no tev listening at {self.host}:{self.port} ({e.strerror or e})")

    def _give_up(self, why):
        warnings.warn(f"preview: {why}; rendering without it", SceneWarning, stacklevel=3)
        self.sock = None

    def update(self, renderer, final=False):
        if self.sock is not None:              # nothing to make for a tev that is gone
            super().update(renderer, final)

    def show(self, result):
        if self.sock is None:
            return
        try:
            for packet in update_packets(self.name, pixels_of(result)):
                self.sock.sendall(packet)
        except OSError as e:
            self.sock.close()
            self._give_up(f"tev at {self.host}:{self.port} went away ({e.strerror or e})")

    def close(self):
        if self.sock is not None:
            self.sock.close()
            self.sock = None
