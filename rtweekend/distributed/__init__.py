"""Rendering on a Dask cluster, bit-identical to a local render: connecting
(cluster.py), the client's driver (client.py) and the workers' tasks (worker.py).
Dask itself is imported only when a cluster is asked for."""
from .cluster import ClusterError, dask_client
from .worker import environment, warm_worker

__all__ = ["ClusterError", "dask_client", "environment", "warm_worker"]
