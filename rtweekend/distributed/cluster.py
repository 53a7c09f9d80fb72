"""Connecting to a Dask cluster: a scheduler's address, or a LocalCluster here.

Dask is imported only when a cluster is asked for (pip install 'rtweekend[dask]').
"""
import logging
import os
import warnings
from contextlib import contextmanager

from ..errors import SceneError, SceneWarning

INSTALL = "pip install 'rtweekend[dask]'"
CONNECT_TIMEOUT = 5.0       # seconds for a scheduler to answer
THREADS_VAR = "RTWEEKEND_NUMBA_THREADS"   # a worker's Numba threads per task (default: all)


class ClusterError(SceneError):
    """A Dask cluster that cannot be used: not installed, unreachable, mismatched.

    A SceneError, so the command reports it in one line with exit status 2.
    """


def no_threads():
    return ClusterError("render: threads does not apply on a Dask cluster (each worker uses "
                        "its NUMBA_NUM_THREADS)")


def distributed_module():
    """Dask's distributed package, imported now (ClusterError if not installed)."""
    try:
        import distributed
    except ImportError:
        raise ClusterError(f"render: rendering on a Dask cluster needs Dask: {INSTALL}") from None
    return distributed


def check_render(scene, threads):
    """What cannot be rendered on a cluster: a classic scene, a thread count."""
    if scene.resolved_integrator() == "classic":
        raise ClusterError("render: a classic scene is ray traced once per pixel, which is "
                           "not worth distributing: render it without --scheduler/--workers")
    if threads is not None:
        raise no_threads()


@contextmanager
def dask_client(scene=None, *, scheduler=None, workers=None, threads=None,
                timeout=CONNECT_TIMEOUT, quiet=True):
    """A Client of the scheduler at `scheduler`, or of a LocalCluster of `workers`
    single-threaded worker processes (closed on exit); None if neither is given.

    scene and threads (the render's) are checked first, before any cluster starts.
    quiet: keep Dask's own log lines off stderr (the command reports in one line).
    """
    if scheduler is None and workers is None:
        yield None
        return
    if scheduler is not None and workers is not None:
        raise ClusterError("render: give either --scheduler or --workers, not both")
    if threads is not None:
        raise no_threads()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ClusterError(f"render: workers must be an integer >= 1, got {workers!r}")
    cores = os.cpu_count() or 1
    if workers is not None and workers > cores:
        warnings.warn(f"--workers {workers} on {cores} cores: the worker processes share "
                      f"them, no faster than {cores}", SceneWarning, stacklevel=3)
    if scene is not None:
        check_render(scene, threads)
    distributed = distributed_module()
    cluster = None
    with _silenced(quiet):
        try:
            if workers is not None:
                # One Numba thread per worker process: N processes share the cores.
                cluster = distributed.LocalCluster(
                    n_workers=workers, threads_per_worker=1, processes=True,
                    dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"},
                    env={THREADS_VAR: "1"},
                    silence_logs=logging.CRITICAL if quiet else logging.WARNING)
                client = distributed.Client(cluster, set_as_default=False)
            else:
                _check_address(scheduler)
                try:
                    client = distributed.Client(scheduler, timeout=timeout,
                                                set_as_default=False)
                except (OSError, ValueError, TypeError) as e:
                    raise ClusterError(f"render: cannot reach the Dask scheduler at "
                                       f"{scheduler}: " + " ".join(str(e).split())) from None
            try:
                yield client
            finally:
                quietly(client.close, timeout=timeout)
        finally:
            if cluster is not None:
                quietly(cluster.close, timeout=timeout)


@contextmanager
def _silenced(quiet):
    """Dask's and Tornado's loggers held at CRITICAL (Dask's config gives some of
    them levels of their own, so each is set), then restored."""
    if not quiet:
        yield
        return
    names = ["distributed", "tornado", "asyncio"] + [
        name for name in list(logging.root.manager.loggerDict)
        if name.startswith(("distributed.", "tornado."))]
    saved = {name: logging.getLogger(name).level for name in names}
    for name in names:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for name, level in saved.items():
            logging.getLogger(name).setLevel(level)


def _check_address(address):
    """A malformed address fails here, before a Client is half made."""
    from distributed.comm import get_address_host_port
    if not isinstance(address, str):
        raise ClusterError(f"render: a Dask scheduler address is a string, got {address!r}")
    if address.startswith("inproc://"):
        return
    try:
        get_address_host_port(address)
    except ValueError as e:
        raise ClusterError(f"render: bad Dask scheduler address {address!r}: "
                           + " ".join(str(e).split()) + " (expected tcp://HOST:PORT)") from None


def quietly(fn, *args, **kwargs):
    """Clean-up that must not hide the real outcome (the cluster may be gone)."""
    try:
        fn(*args, **kwargs)
    except Exception:
        pass
