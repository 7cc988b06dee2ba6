"""Sweeps on a dask cluster: the same tasks as the local process pool, spread over its workers.

``on_cluster(scheduler, task, tasks, context)`` runs ``task(item, context)`` for every item on
the ``distributed`` cluster whose scheduler is at ``scheduler`` (an address such as
``tcp://10.0.0.5:8786``, or a ``distributed.Client``/``LocalCluster``) and yields the results as
they complete. The context (the kernel, the function and its precision) is sent once to every
worker; a reactor kernel pickles as its recipe and is built there for that worker's CPU.
Needs the ``distributed`` extra (``pip install "reactor-simd[distributed]"``).
"""
from __future__ import annotations

from reactor import ReactorError


def on_cluster(scheduler, task, tasks, context):
    """Yield ``task(item, context)`` for each of ``tasks``, computed on the cluster, as they complete."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ReactorError('--scheduler needs dask.distributed: pip install "reactor-simd[distributed]"') from None
    own = not isinstance(scheduler, Client)
    client = Client(scheduler) if own else scheduler
    try:
        shared = client.scatter(context, broadcast=True)
        futures = client.map(task, tasks, context=shared, pure=False)
        for future in as_completed(futures):
            yield future.result()
    finally:
        if own:
            client.close()
