"""The Dask client that pf_tune and benchmark_datasets run their tasks on.

A task is a function of this package (pf_localization.tune_tasks.evaluate_bag,
pf_localization.benchmark.run_one): Dask sends it by name, so every worker must import the
pf_localization Python package. The LocalCluster's worker processes inherit the tool's sys.path;
a worker of a cluster started by hand needs the workspace's setup.bash sourced.
"""
import os


class ClusterError(Exception):
    """The cluster cannot be reached or started; the tools print it and exit with status 2 (pf_tune)
    or 1 (benchmark_datasets)."""


def open_client(scheduler=None, workers=None, quiet=True):
    """A dask.distributed Client: on the cluster at `scheduler`, or on a LocalCluster of `workers`
    single-threaded worker processes (default one per core) that closes with the client."""
    import logging
    from distributed import Client, LocalCluster
    if scheduler:
        try:
            return Client(scheduler, timeout='20s')
        except (OSError, TimeoutError) as e:
            raise ClusterError('cannot reach the Dask scheduler at %s: %s' % (scheduler, e))
    n = workers or os.cpu_count() or 1
    # No dashboard, and the scheduler's HTTP server (which runs even without one) on a free port
    # of localhost: a second pf_tune, or another Dask user, has 8787.
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host='127.0.0.1',
                           dashboard_address=None, scheduler_kwargs={'dashboard_address': '127.0.0.1:0'},
                           memory_limit=0, silence_logs=logging.ERROR if quiet else logging.WARNING)
    client = Client(cluster)
    client._pf_own_cluster = cluster
    return client


def close_client(client):
    """Closes the client, and the LocalCluster open_client started for it."""
    cluster = getattr(client, '_pf_own_cluster', None)
    client.close()
    if cluster is not None:
        cluster.close()
