"""The tev preview (io/tev.py), against a fake tev: a socket server that
parses the IPC packets as tev does and rebuilds the image from the tiles."""
import socket
import struct
import threading

import numpy as np
import pytest

import rtweekend as rt


class FakeTev:
    """Accepts one connection and parses CreateImage / UpdateImage packets."""

    def __init__(self):
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.created, self.tiles, self.image = None, 0, None
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        conn, _ = self.server.accept()
        data = b""
        with conn:
            while chunk := conn.recv(1 << 16):
                data += chunk
                while len(data) >= 4 and len(data) >= struct.unpack("<I", data[:4])[0]:
                    size = struct.unpack("<I", data[:4])[0]
                    self._packet(data[4:size])
                    data = data[size:]

    @staticmethod
    def _string(buf, at):
        end = buf.index(b"\0", at)
        return buf[at:end].decode(), end + 1

    def _packet(self, p):
        kind, at = p[0], 2                       # type, grab focus
        name, at = self._string(p, at)
        if kind == 4:
            w, h, n = struct.unpack_from("<iii", p, at)
            at += 12
            names = []
            for _ in range(n):
                c, at = self._string(p, at)
                names.append(c)
            self.created = (name, w, h, names)
            self.image = np.zeros((h, w, n), np.float32)
            self.tiles = 0
        elif kind == 6:
            (n,) = struct.unpack_from("<i", p, at)
            at += 4
            for _ in range(n):
                _, at = self._string(p, at)
            x, y, w, h = struct.unpack_from("<iiii", p, at)
            at += 16
            offsets = struct.unpack_from(f"<{n}q", p, at)
            strides = struct.unpack_from(f"<{n}q", p, at + 8 * n)
            assert offsets == tuple(range(n)) and strides == (n,) * n
            pixels = np.frombuffer(p, "<f4", h * w * n, at + 16 * n).reshape(h, w, n)
            self.image[y:y + h, x:x + w] = pixels
            self.tiles += 1

    def join(self):
        self.thread.join(timeout=30)
        self.server.close()


def test_the_image_and_its_error_stream_to_tev():
    tev = FakeTev()
    scene = rt.load_scene("cornell_box")
    # 300 x 200: tiles of 128 on both axes, the last ones partial.
    r = rt.render(scene, spp=8, width=300, height=200, seed=3,
                  preview=f"tev://127.0.0.1:{tev.port}")
    tev.join()
    assert tev.tiles > 0 and tev.tiles % (3 * 2) == 0        # whole images of 3 x 2 tiles
    name, w, h, channels = tev.created
    assert (name, w, h) == ("cornell_box", 300, 200)
    assert channels == ["R", "G", "B", "stderr.R", "stderr.G", "stderr.B"]
    assert np.array_equal(tev.image[..., :3], r.image)
    assert np.array_equal(tev.image[..., 3:], r.stderr)
    plain = rt.render(scene, spp=8, width=300, height=200, seed=3)
    assert np.array_equal(plain.image, r.image)


def test_no_tev_listening_is_one_warning_and_the_render_goes_on():
    with socket.create_server(("127.0.0.1", 0)) as s:
        port = s.getsockname()[1]              # closed below: nothing listens there
    with pytest.warns(rt.SceneWarning, match=f"no tev listening at 127.0.0.1:{port}"):
        r = rt.render(rt.load_scene("cornell_box"), spp=2, width=16, height=16,
                      preview=f"tev://127.0.0.1:{port}")
    assert r.stats.spp == 2


@pytest.mark.parametrize("spec", ["tev://nohost", "tev://h:0", "tev://h:x", "nonsense"])
def test_a_bad_tev_address_is_one_line(spec):
    with pytest.raises(rt.SceneError, match="preview: "):
        rt.render(rt.load_scene("cornell_box"), spp=1, width=4, height=4, preview=spec)


def test_ctrl_c_leaves_the_last_image_shown():
    import os
    import signal
    tev = FakeTev()
    timer = threading.Timer(1.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    r = rt.render(rt.load_scene("cornell_box"), spp=100000, width=64, height=64, seed=4,
                  preview=f"tev://127.0.0.1:{tev.port}")
    timer.join()
    tev.join()
    assert r.stats.interrupted and 0 < r.stats.spp < 100000
    assert np.array_equal(tev.image[..., :3], r.image)     # what was returned is shown
