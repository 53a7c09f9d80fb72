"""What a live preview costs: the time of one update against the render.

    python benchmarks/preview.py [--size 300] [--runs 20] [--quick]

An update of the notebook preview (io/preview.py) makes the result so far and
its PNG and HTML (RenderResult._repr_html_); one of the tev preview (io/tev.py)
makes the result and its packets.  The passes wait for it, so at one update per
MIN_INTERVAL the share of the render it costs is at most update / MIN_INTERVAL.
Measured on cornell_box at --size x --size after 4 spp: the median of --runs
updates each, and that share.  Writes benchmark-results/preview.json.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, median_seconds, parser, save_json  # noqa: E402

import rtweekend as rt  # noqa: E402
from rtweekend.io import preview, tev  # noqa: E402


def main(argv=None):
    p = parser(__doc__)
    p.add_argument("--size", type=int, default=300)
    p.add_argument("--runs", type=int, default=20)
    a = p.parse_args(argv)
    size, runs = (32, 3) if a.quick else (a.size, a.runs)
    r = rt.Renderer(rt.load_scene("cornell_box"), width=size, height=size, seed=1)
    r.add_samples(4)

    def notebook_update():
        r.result(denoise=False)._repr_html_()

    def tev_update():
        sum(len(b) for b in tev.update_packets("x", tev.pixels_of(r.result(denoise=False))))

    data = dict(machine=machine(), size=size, runs=runs, updates={})
    for name, fn, interval in (("notebook", notebook_update, preview.MIN_INTERVAL),
                               ("tev", tev_update, tev.MIN_INTERVAL)):
        fn()                                         # warm-up
        s = median_seconds(fn, runs)
        data["updates"][name] = dict(seconds=s, interval=interval, share=s / interval)
        print(f"{name:9s} update {1000 * s:6.1f} ms at {size}x{size}: at most "
              f"{100 * s / interval:.1f}% of a render at one update per {interval} s")
    save_json("preview.json", data, a.out)


if __name__ == "__main__":
    main()
