"""A 1,000-point Monte Carlo sweep of the double pendulum's initial angle on Dask.

The double pendulum (HW19) is chaotic: a change of the upper bar's initial angle by 1e-4 rad
changes where the lower bar is after 10 s by radians. This sweep spreads θ1(0) over ±0.1 rad,
runs the 1,000 simulations on a Dask cluster, checks the result against the serial loop bit
for bit and prints how far the final angles spread.

    python python/examples/monte_carlo_dask.py                      # a LocalCluster on this machine
    python python/examples/monte_carlo_dask.py tcp://10.0.0.5:8786  # a running cluster's scheduler

On a cluster, install the same eomgen wheel on every worker (the model travels pickled, by its
file's text and parameters, and is compiled again there once per worker process).
"""

import sys
import time

import numpy as np
from distributed import Client, LocalCluster

import eomgen


def main(address=None):
    m = eomgen.load("double_pendulum")
    states = np.tile(m.initial_state(), (1000, 1))
    states[:, 0] += np.linspace(-0.1, 0.1, 1000)
    options = dict(t_end=10.0, t_out=[10.0], rtol=1e-10, atol=1e-10)

    if address is None:
        # Loopback only, ports picked by the system, no dashboard; one process per core.
        cluster = LocalCluster(host="127.0.0.1", n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        cluster, client = None, Client(address, timeout="30s")
    try:
        start = time.perf_counter()
        batch = eomgen.sweep.run(client, m, initial_states=states, **options)
        elapsed = time.perf_counter() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    serial = np.array([m.simulate(initial=y0, **options).y for y0 in states])
    assert np.array_equal(batch.y, serial), "the sweep differs from the serial loop"
    theta2 = batch.q[:, -1, 1]
    print(f"{len(batch)} runs in {elapsed:.2f} s on the cluster; equal to the serial loop bit for bit")
    print(f"θ2(10 s) ranges over [{theta2.min():.3f}, {theta2.max():.3f}] rad for θ1(0) within ±0.1 rad")


if __name__ == "__main__":  # required: the workers are started by spawning this script
    main(sys.argv[1] if len(sys.argv) > 1 else None)
