"""The benchmark scripts run (tiny versions) and write what they promise."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import REPO


def _references(folder, names=("cornell_box_300", "cornell_glass_150")):
    """The Mitsuba references as benchmarks/accuracy.py reads them (name.npy and
    name_stderr.npy), written from the copies in tests/data/reference."""
    folder.mkdir()
    for name in names:
        with np.load(REPO / "tests" / "data" / "reference" / f"{name}.npz") as f:
            np.save(folder / f"{name}.npy", f["radiance"])
            np.save(folder / f"{name}_stderr.npy", f["stderr"])
    return folder


def _accuracy(out, references, *args):
    env = dict(os.environ, RTWEEKEND_REFERENCES=str(references))
    return subprocess.run([sys.executable, str(REPO / "benchmarks" / "accuracy.py"), "--quick",
                           "--out", str(out), *args], capture_output=True, text=True,
                          timeout=600, env=env)


def test_accuracy_benchmark_quick(tmp_path):
    from rtweekend.options import SAMPLINGS
    r = _accuracy(tmp_path, _references(tmp_path / "references"))
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "accuracy.json").read_text())
    assert set(data["scenes"]) == {"cornell_box", "cornell_glass"}
    for scene in data["scenes"].values():
        assert "Mitsuba" in scene["reference"] and "independent" in scene["reference"]
        assert set(scene["curves"]) == set(SAMPLINGS)
        for rows in scene["curves"].values():
            assert [p["spp"] for p in rows][:3] == [1, 2, 4]
            assert all(p["rmse"] > 0 and p["nan_fraction"] == 0 for p in rows)
            times = [p["seconds"] for p in rows]
            assert times == sorted(times)
        den = scene["denoised"]             # the denoise extra is in the test extra
        assert den["sampling"] in scene["curves"] and [p["spp"] for p in den["rows"]][:3] == \
            [1, 2, 4]
        assert all(p["rmse"] > 0 and p["seconds"] > p["render_seconds"] for p in den["rows"])
        assert (den["peer"] is None) == (scene["peer"] is None)
        if scene["peer"] is None:            # Mitsuba is optional: one line says so
            assert scene["vs_peer"] == []
            assert "Mitsuba not installed: pip install '.[peer]'" in r.stdout
        else:
            assert [p["spp"] for p in scene["peer"]["rows"]] == [1, 2, 4]
            assert len(scene["vs_peer"]) == 3
    for name in ("accuracy.png", "accuracy_crops.png"):
        assert (tmp_path / name).stat().st_size > 10_000


def test_accuracy_benchmark_skips_a_scene_without_its_reference(tmp_path):
    # One without a reference is skipped in one line; none at all: exit 2, nothing written.
    refs = _references(tmp_path / "some", names=("cornell_box_300",))
    r = _accuracy(tmp_path / "one", refs, "--no-peer")
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("(set RTWEEKEND_REFERENCES); skipped") == 1
    assert list(json.loads((tmp_path / "one" / "accuracy.json").read_text())["scenes"]) == \
        ["cornell_box"]
    r = _accuracy(tmp_path / "none", tmp_path / "nowhere", "--no-peer")
    assert r.returncode == 2
    assert r.stderr.strip().splitlines()[-1].startswith("accuracy: no reference for any of "
                                                        "cornell_box, cornell_glass")
    assert not (tmp_path / "none" / "accuracy.json").exists()


def test_throughput_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "throughput.py"), "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "throughput.json").read_text())
    glass = data["scenes"]["cornell_glass"]
    assert glass["1_thread"]["samples_per_s"] > 0 and glass["all_threads"]["samples_per_s"] > 0
    assert glass["mean_path_length"] >= 1 and glass["peak_rss_mb"] > 0
    assert data["scenes"]["cgfs"]["integrator"] == "classic"
    assert data["compile"]["cached"]["total_s"] > 0
    assert set(data["verdict"]) == set(data["targets"])
    assert data["weekend_bvh"]["speedup"] > 0
    assert (tmp_path / "throughput.png").stat().st_size > 10_000


def test_dask_overhead_benchmark_quick(tmp_path):
    pytest.importorskip("distributed", reason="needs Dask: pip install 'rtweekend[dask]'")
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "dask_overhead.py"),
                        "--quick", "--out", str(tmp_path)], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "distributed.json").read_text())
    assert [row["spp"] for row in data["rows"]] == [20, 40]
    assert all(row["identical"] for row in data["rows"])
    idle = data["idle_cluster"]
    assert idle["alone"] > 0 and idle["idle_cluster"] > 0
    assert idle["slowdown"] == pytest.approx(1 - idle["idle_cluster"] / idle["alone"])


def test_sobol_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "sobol.py"), "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "sobol.json").read_text())
    assert set(data["cost"]) == {"sobol.sample_2d", "sobol.sample_1d", "rng.uniform pair",
                                 "rng.seed_state + uniform pair"}
    assert all(row["ns_per_sample"] > 0 for row in data["cost"].values())
    assert data["slopes"]["smooth exp(uv), sobol"]["slope"] < -1.0
    assert data["slopes"]["smooth exp(uv), rng"]["slope"] > -0.7


def test_precision_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "precision.py"), "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""                      # no NumPy warnings either
    data = json.loads((tmp_path / "precision.json").read_text())
    assert set(data["scenes"]) == {"cornell_glass", "cornell_box", "weekend"}
    for s in data["scenes"].values():
        assert s["float64"]["rays_per_s"] > 0 and s["float32"]["rays_per_s"] > 0
        assert 0 <= s["different_nearest_object"] < s["rays"] / 100


def test_precision_probe_is_the_renderers_search_in_true_float32():
    """The probe runs the renderer's own closest_hit: in float64 it finds what
    the renderer finds, and its float32 build computes in single precision (no
    double arithmetic in its assembly)."""
    import re

    import numba
    import numpy as np
    from numba import types

    import rtweekend as rt
    from rtweekend.path.bvh import closest_hit
    sys.path.insert(0, str(REPO / "benchmarks"))
    try:
        import precision
    finally:
        sys.path.pop(0)
    a, o, d, left = precision.rays_for(rt.load_scene("cornell_glass"), 24, 24, seed=3)
    hits = precision.nearest(*precision.arguments(a, np.float64, o, d, left))
    nearest = numba.njit(lambda a, o, d, left: closest_hit(a, o, d, np.inf, left, False, None)[0])
    for r in range(0, len(o), 5):
        assert nearest(a, tuple(o[r]), tuple(d[r]), left[r]) == hits[r], r
    assert (hits != precision.NO_HIT).sum() > len(o) // 2
    precision.nearest(*precision.arguments(a, np.float32, o, d, left))
    sig = [s for s in precision.nearest.signatures if s[1].dtype == types.float32][0]
    asm = precision.nearest.inspect_asm(sig)
    assert re.findall(r"\bv?(?:mul|add|sub|div|sqrt)ss\b", asm)
    assert not re.findall(r"\bv?(?:mul|add|sub|div|sqrt)sd\b", asm)


def test_paired_benchmark_compares_trees_in_one_process():
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "paired.py"), "trees",
                        str(REPO), "--quick", "--scene", "metals", "--sampling", "cosine"],
                       capture_output=True, text=True, timeout=600, cwd=REPO.parent)
    assert r.returncode == 0, r.stderr
    line = r.stdout.strip().splitlines()[-1]
    assert "M samples/s, 1.000x the first" in line, r.stdout


def test_paired_benchmark_without_the_yardstick_says_so(tmp_path):
    env = dict(os.environ, RTWEEKEND_YARDSTICK=str(tmp_path / "nowhere.py"))
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "paired.py"), "yardstick",
                        "--quick", "--out", str(tmp_path)], capture_output=True, text=True,
                       timeout=600, env=env)
    assert r.returncode == 0, r.stderr
    assert "yardstick not found at" in r.stdout
    assert not (tmp_path / "paired.json").exists()


FAKE_YARDSTICK = '''import os
DT = os.environ.get("PROBE_DTYPE", "f32"); FMODE = os.environ.get("PROBE_FM", "safe")
FM = {"safe": {"nsz", "reassoc", "contract"},
      "fast": True}[FMODE]
'''


def test_the_yardstick_is_built_with_rtweekends_flags_in_both_precisions(tmp_path, monkeypatch):
    sys.path.insert(0, str(REPO / "benchmarks"))
    import yardstick
    from rtweekend.kernel.jit import FASTMATH
    fake = tmp_path / "fake_probe.py"
    fake.write_text(FAKE_YARDSTICK)
    monkeypatch.setattr(yardstick, "PATH", fake)
    monkeypatch.setattr(yardstick, "BUILD_FOLDER", tmp_path / "builds")
    monkeypatch.delenv("PROBE_FM", raising=False)
    shipped = yardstick.load("shipped")
    assert (shipped.FM, shipped.DT) == ({"nsz", "reassoc", "contract"}, "f32")
    f32, f64 = yardstick.load("rtweekend_flags"), yardstick.load("rtweekend_flags_f64")
    assert (f32.FM, f32.DT) == (FASTMATH, "f32")
    assert (f64.FM, f64.DT) == (FASTMATH, "f64")
    assert f32.__file__ != f64.__file__ != str(fake)     # a Numba cache each
    assert "PROBE_FM" not in os.environ
    fake.write_text("FM = {}\n")
    with pytest.raises(RuntimeError, match="fake_probe.py: its table of fastmath sets"):
        yardstick.load("rtweekend_flags")


# Writes [1, 2, 3] the first time it runs with a Numba cache folder, [1, 2, 4] once
# that folder holds something: a command whose later runs differ from its first.
CACHE_AWARE = '''import os, sys, numpy as np
cache = os.environ["NUMBA_CACHE_DIR"]
again = os.path.isdir(cache)
os.makedirs(cache, exist_ok=True)
np.save(sys.argv[1] + ".npy", np.array([1.0, 2.0, 4.0 if again else 3.0]))
'''


def test_first_render_and_next_share_one_empty_cache_folder():
    sys.path.insert(0, str(REPO / "benchmarks"))
    from common import first_render_and_next
    assert first_render_and_next([sys.executable, "-c", CACHE_AWARE]) == (1, 3)
    same = "import sys, numpy as np; np.save(sys.argv[1] + '.npy', np.arange(5.0))"
    assert first_render_and_next([sys.executable, "-c", same]) == (0, 5)


def test_accuracy_quick_measures_against_the_reference_over_blocks_of_pixels():
    # --quick renders a third (or half) of the reference's size: each of its
    # pixels is a block of the reference's, whose mean and standard error it
    # is measured against.
    sys.path.insert(0, str(REPO / "benchmarks"))
    import accuracy
    rng = np.random.default_rng(3)
    ref, se = rng.random((6, 9, 3)), rng.random((6, 9, 3))
    mean, err = accuracy.block_means(ref, se, 3)
    assert mean.shape == err.shape == (2, 3, 3)
    np.testing.assert_allclose(mean[1, 2], ref[3:6, 6:9].mean(axis=(0, 1)))
    np.testing.assert_allclose(err[1, 2], np.sqrt((se[3:6, 6:9] ** 2).sum(axis=(0, 1))) / 9)
    assert accuracy.block_means(ref, se, 1) == (ref, se)
    for name, cfg in accuracy.QUICK.items():
        full = accuracy.FULL[name]
        assert cfg["shrink"] > 1 and cfg["width"] * cfg["shrink"] == full["width"]
        assert cfg["height"] * cfg["shrink"] == full["height"]


def test_accuracy_summary_when_the_base_starts_after_the_equal_time(capsys):
    # A short run on a busy machine: the base's first pass took longer than the
    # whole curve of another strategy, so its error at that time is unknown.
    sys.path.insert(0, str(REPO / "benchmarks"))
    import accuracy
    curves = {"mixture+sobol": [dict(spp=1, seconds=0.5, rmse=0.2),
                                dict(spp=2, seconds=0.9, rmse=0.1)],
              "cosine": [dict(spp=1, seconds=0.1, rmse=0.4), dict(spp=2, seconds=0.3, rmse=0.3)]}
    eq = accuracy.equal_time(curves)
    assert eq["seconds"] == 0.3 and eq["rmse"]["mixture+sobol"] is None
    assert accuracy.time_factor(eq, "cosine") == "mixture+sobol not measured this early"
    accuracy.summary(dict(total_seconds=1.0, scenes={"cornell_box": dict(
        equal_time=eq, slopes={"cosine": -0.5}, peer=None, vs_peer=None)}))
    assert "cosine RMSE 0.3000 (mixture+sobol not measured this early)" in capsys.readouterr().out
    eq = accuracy.equal_time({"mixture+sobol": curves["mixture+sobol"],
                              "cosine": [dict(spp=1, seconds=0.5, rmse=0.4)]})
    assert accuracy.time_factor(eq, "cosine") == "4.00x mixture+sobol's time for its error"


def test_compile_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "compile.py"), "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-2000:]
    lines = r.stdout.splitlines()
    assert lines[1].startswith("cornell_box") and lines[2].startswith("cgfs")
    assert "sum of the cold starts" in lines[-1]


def test_strategies_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "strategies.py"), "--quick",
                        "--threads", "1", "--out", str(tmp_path)], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "strategies.json").read_text())
    assert len(data["scenes"]) == 2
    for row in data["scenes"].values():
        got = row["strategies"]
        assert got[data["default"]]["ratio_to_default"] == 1.0
        assert all(v["rmse"] > 0 and v["spp"] >= 1 for v in got.values())
        assert row["lowest"] in got


def test_denoise_benchmark_quick(tmp_path):
    pytest.importorskip("pyoidn", reason="needs the denoise extra")
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "denoise.py"), "--quick",
                        "--no-peer", "--threads", "1", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "denoise.json").read_text())
    assert [row["spp"] for row in data["errors"]] == [1, 2]
    assert all(0 < v for row in data["errors"] for v in row["denoised"].values())
    for row in data["errors"]:              # without the reference's noise: no larger
        assert 0 <= row["raw_clean"] <= row["raw"]
        assert all(0 <= row["denoised_clean"][w] <= v for w, v in row["denoised"].items())
    assert [row["spp"] for row in data["curves"]] == [1, 2, 4]
    assert data["peer"] is None and 0 < data["cost"]["share"]
    assert (tmp_path / "denoise.png").stat().st_size > 10_000


def test_preview_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "preview.py"), "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "preview.json").read_text())
    assert set(data["updates"]) == {"notebook", "tev"}
    assert all(0 < u["share"] < 1 for u in data["updates"].values())


def test_light_pick_benchmark_quick(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "light_pick.py"), "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    lines = [line for line in r.stdout.splitlines() if "efficiency x" in line]
    assert [line.split()[0] for line in lines] == ["simple_light", "bright_and_dim"]


def _profile_kernel():
    sys.path.insert(0, str(REPO / "benchmarks"))
    try:
        import profile_kernel
    finally:
        sys.path.remove(str(REPO / "benchmarks"))
    return profile_kernel


def test_profile_kernel_names_the_function_around_a_line(tmp_path):
    """A sampled address's source line goes to the function whose body holds it
    (the innermost one), a line-less frame to its file alone."""
    profile_kernel = _profile_kernel()
    bvh = REPO / "rtweekend" / "path" / "bvh.py"
    lines = bvh.read_text().splitlines()
    body = next(i for i, line in enumerate(lines, 1) if "def nearest_in_leaf(" in line) + 4
    assert profile_kernel.function_at(f"{bvh}:{body}") == "path/bvh.py:nearest_in_leaf"
    assert profile_kernel.function_at(f"{bvh}:?") == "path/bvh.py"
    nested = tmp_path / "nested.py"
    nested.write_text("def outer():\n    def inner():\n        return 1\n    return inner\n")
    assert profile_kernel.function_at(f"{nested}:3") == "nested.py:inner"
    assert profile_kernel.function_at(f"{nested}:4") == "nested.py:outer"


def test_profile_kernel_without_perf_says_so_in_one_line(tmp_path):
    env = dict(os.environ, PATH=str(tmp_path))        # no perf, no binutils
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "profile_kernel.py"),
                        "--quick", "--out", str(tmp_path)], capture_output=True, text=True,
                       timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines() == [
        "profile_kernel: needs perf, addr2line, nm (Linux perf, binutils); not run"]


def test_profile_kernel_reads_callgrind_instruction_costs(tmp_path):
    """A dump with --dump-instr=yes compresses positions (absolute, +/-
    relative to the last, * the same) and follows a `calls=` line with the
    callee's inclusive cost, which is not the instruction's own."""
    dump = tmp_path / "callgrind.out.1"
    dump.write_text("positions: instr line\nevents: Ir\nfn=(1) kernel\n"
                    "0x7f0000001000 12 3\n+4 * 2\n* +1 5\n-2 * 7\n"
                    "calls=1 0x7f0000002000 40\n+6 * 1000\n+3 * 1\nsummary: 1018\n")
    costs = _profile_kernel().callgrind_costs(dump)
    assert costs == {0x7f0000001000: 3, 0x7f0000001004: 7, 0x7f0000001002: 7,
                     0x7f000000100b: 1}


def test_profile_kernel_reads_one_event_of_a_branch_simulation(tmp_path):
    """With --branch-sim=yes each line has five counts (Ir Bc Bcm Bi Bim), its
    trailing zeros left out; --branches reads the mispredicted ones (Bcm)."""
    dump = tmp_path / "callgrind.out.1"
    dump.write_text("positions: instr line\nevents: Ir Bc Bcm Bi Bim\nfn=(1) kernel\n"
                    "0x7f0000001000 12 3\n+4 * 2 1 1\n* +1 5 2\n+2 * 1 1 0 1 1\n"
                    "calls=1 0x7f0000002000 40\n+6 * 1000 90 9\n+3 * 1 1 1\n")
    pk = _profile_kernel()
    assert pk.callgrind_costs(dump, "Bcm") == {0x7f0000001004: 1, 0x7f0000001006: 0,
                                               0x7f000000100f: 1}
    assert pk.callgrind_costs(dump, "Bim") == {0x7f0000001006: 1}
    assert pk.callgrind_costs(dump) == {0x7f0000001000: 3, 0x7f0000001004: 7,
                                        0x7f0000001006: 1, 0x7f000000100f: 1}


def test_profile_kernel_classes_instructions_by_opcode():
    cls = _profile_kernel().opcode_class
    assert cls("vmulsd", "0x10(%rsp),%xmm1,%xmm2") == "stack load"
    assert cls("vmovsd", "%xmm0,0x158(%rsp)") == "stack store"
    assert cls("mov", "0xab0(%rsp),%r8") == "stack load"
    assert cls("vdivsd", "%xmm1,%xmm13,%xmm0") == "floating point"
    assert cls("mov", "(%r8,%rdi,8),%rdi") == "other move"
    assert cls("jle", "0x2475ed74") == "jump"
    assert cls("cmp", "$0x5,%r8") == "compare"
    assert cls("imul", "%r12,%rdi") == "other integer"


def test_profile_kernel_names_the_step_of_the_path_loop():
    """An instruction counts for the function called on trace's line of its
    inline chain (innermost first)."""
    pk = _profile_kernel()
    def line_in(path, function):
        lines = path.read_text().splitlines()
        return next(i for i, line in enumerate(lines, 1) if f"def {function}(" in line) + 4
    bvh = REPO / "rtweekend" / "path" / "bvh.py"
    path = REPO / "rtweekend" / "path" / "integrators" / "path.py"
    chain = [f"{bvh}:{line_in(bvh, 'nearest_in_leaf')}", f"{path}:{line_in(path, 'trace')}",
             f"{path}:{line_in(path, 'camera_sample')}"]
    assert pk._step(chain) == "nearest_in_leaf"
    assert pk._step(chain[1:]) == "trace (its own lines)"
    assert pk._step(chain[2:]) == "outside trace"


def test_profile_kernel_count_without_valgrind_says_so_in_one_line(tmp_path):
    env = dict(os.environ, PATH=str(tmp_path))
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "profile_kernel.py"),
                        "--count", "--out", str(tmp_path)], capture_output=True, text=True,
                       timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines() == [
        "profile_kernel: --count needs valgrind, callgrind_control, addr2line, nm, objdump; "
        "not run"]


# -- the Mitsuba 3 scripts (the peer and the references' makers) -------------------

def _mitsuba(script, *args, cwd=None):
    pytest.importorskip("mitsuba", reason="needs the peer extra")
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / script), "--quick", *args],
                       capture_output=True, text=True, timeout=600, cwd=cwd)
    assert r.returncode == 0, r.stderr[-2000:]
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_mitsuba_reference_quick_agrees_with_rtweekend(tmp_path):
    info = _mitsuba("mitsuba_reference.py", "cornell_box", "--out", str(tmp_path / "box"))
    assert info["spp_done"] == 64 and info["passes_done"] == 4
    image, stderr = np.load(tmp_path / "box.npy"), np.load(tmp_path / "box_stderr.npy")
    assert image.shape == stderr.shape == (16, 16, 3) and np.isfinite(image).all()
    assert (tmp_path / "box.png").stat().st_size > 0
    # The independent renderer and ours see the same room: their means agree
    # within 5 standard errors of the difference of the means.
    import rtweekend as rt
    ours = rt.render(rt.load_scene("cornell_box"), spp=256, width=16, height=16, seed=1)
    n = image.size
    sigma = np.sqrt((stderr ** 2).sum() + (ours.stderr.astype(np.float64) ** 2).sum()) / n
    assert abs(image.mean() - ours.image.mean()) < 5 * sigma, (image.mean(), ours.image.mean())


def test_mitsuba_smoke_reference_quick(tmp_path):
    info = _mitsuba("mitsuba_smoke.py", "--out", str(tmp_path / "smoke"))
    assert info["spp_done"] == 64 and info["stencil_below_floor"] > 0
    image = np.load(tmp_path / "smoke.npy")
    assert image.shape == (16, 16, 3) and np.isfinite(image).all() and image.mean() > 0


def test_mitsuba_peer_quick_series_with_features(tmp_path):
    info = _mitsuba("mitsuba_peer.py", "cornell_glass", "--series", "--aov", "--save",
                    str(tmp_path / "peer.npz"))
    assert info["available"] and info["spp"] == [1, 2, 4] and info["width"] == 16
    with np.load(tmp_path / "peer.npz") as f:
        assert f["images"].shape == (3, 16, 16, 9) and list(f["spp"]) == [1, 2, 4]
        assert np.isfinite(f["images"]).all()


def test_meshes_benchmark_quick(tmp_path):
    pytest.importorskip("trimesh", reason="needs the meshes extra")
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "meshes.py"), "--quick",
                        "--runs", "1", "--out", str(tmp_path)], capture_output=True, text=True,
                       timeout=900)
    assert r.returncode == 0, r.stderr[-2000:]
    data = json.loads((tmp_path / "meshes.json").read_text())
    assert data["build"]["triangles"] > 10_000 and data["build"]["rtweekend_bvh_s"] > 0
    for kind in ("camera", "diffuse"):
        row = data["traversal"][kind]
        assert row["rtweekend_rays_per_s"] > 0 and row["hit_fraction"] > 0.05
        if "embree_hit_fraction" in row:       # the same rays meet the same mesh
            assert abs(row["embree_hit_fraction"] - row["hit_fraction"]) < 0.01
    assert data["whole"]["rtweekend_wall_s"] > 0


def test_profile_kernel_keeps_the_code_numba_debug_mode_changes(tmp_path):
    """Debug records without the rest of Numba's debug mode: a helper is still
    inlined into its caller, and a step's array index is not checked against
    the bounds (the profiled code is the one that runs).  In a process of its
    own: the change is to Numba, for the whole process."""
    probe = tmp_path / "probe.py"
    probe.write_text("""
import sys, numba
import numpy as np
sys.path.insert(0, sys.argv[1])
import profile_kernel
if sys.argv[2] == "keep":
    profile_kernel.keeping_the_code()
from rtweekend.kernel.jit import jit_step
@numba.njit
def half(x):
    return 0.5 * x
@numba.njit
def quarter(x):
    return half(half(x))
assert quarter(8.0) == 2.0
@jit_step
def at(a, i):
    return a[i]
try:
    at(np.zeros(4)[:2], 2)          # past the view's end, inside the buffer
    checked = 0
except IndexError:
    checked = 1
ir = next(iter(quarter.inspect_llvm().values()))
print(checked, sum("call" in line and "4half" in line for line in ir.splitlines()))
""")
    found = {}
    for mode in ("stock", "keep"):
        env = dict(os.environ, NUMBA_DEBUGINFO="1", NUMBA_CACHE_DIR=str(tmp_path / mode))
        r = subprocess.run([sys.executable, str(probe), str(REPO / "benchmarks"), mode],
                           capture_output=True, text=True, timeout=300, env=env)
        assert r.returncode == 0, r.stderr
        found[mode] = [int(v) for v in r.stdout.split()[-2:]]
    assert found["stock"][0] == 1   # Numba's debug mode: indices checked
    assert found["stock"][1] > 0    # and the helper stays a call
    assert found["keep"] == [0, 0]
