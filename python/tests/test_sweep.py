"""Sweeps on a Dask LocalCluster and on a process pool, against the serial loop bit for bit.

The cluster binds the loopback interface only, on ports the system picks, with no dashboard:
nothing listens on a public interface and parallel runs cannot collide.
"""

import concurrent.futures
import pickle

import numpy as np
import pytest

import eomgen

distributed = pytest.importorskip("distributed")

# 3 s: the final angles of the lower bar already spread over 7.5 rad from the ±0.1 rad of the
# upper bar's start (10 s cost 3.3 times as much in CI's debug build, for the same check).
T_END = 3.0
TOL = 1e-10


def monte_carlo_states(model, count):
    """`count` initial states: the file's, with the upper bar's angle spread by ±0.1 rad
    (the double pendulum's sensitivity to its initial angle)."""
    states = np.tile(model.initial_state(), (count, 1))
    states[:, 0] += np.linspace(-0.1, 0.1, count)
    return states


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(host="127.0.0.1", n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, scheduler_port=0, memory_limit="2GiB",
                                  silence_logs=40) as cluster, \
            distributed.Client(cluster, timeout="60s") as client:
        yield client


def test_a_1000_point_monte_carlo_on_dask_equals_the_serial_loop(client):
    m = eomgen.load("double_pendulum")
    states = monte_carlo_states(m, 1000)
    batch = eomgen.sweep.run(client, m, initial_states=states, t_end=T_END, t_out=[T_END], rtol=TOL, atol=TOL)
    assert batch.y.shape == (1000, 1, 4) and batch.ok.all()
    serial = np.array([m.simulate(t_end=T_END, t_out=[T_END], initial=y0, rtol=TOL, atol=TOL).y for y0 in states])
    assert np.array_equal(batch.y, serial)
    # The sweep shows what it is for: the final angle depends on the initial one, chaotically.
    assert np.ptp(batch.q[:, -1, 1]) > 1.0


def test_a_parameter_sweep_with_a_file_model_on_dask(client, model_file):
    m = eomgen.load(model_file("simple_pendulum"))
    gs = np.linspace(1.0, 20.0, 40)
    batch = eomgen.sweep.run(client, m, parameters={"g": gs}, t_end=2.0, t_out=[1.0, 2.0])
    local = m.simulate_many(parameters={"g": gs}, t_end=2.0, t_out=[1.0, 2.0])
    assert np.array_equal(batch.y, local.y)


def test_a_failure_on_a_worker_reaches_the_client_whole(client):
    m = eomgen.load("triple_pendulum")
    states = np.tile(m.initial_state(), (4, 1))
    with pytest.raises(eomgen.IntegrationError) as info:
        eomgen.sweep.run(client, m, initial_states=states, method="rk4", dt=0.5)
    assert info.value.t is not None and len(info.value.solution.failures) == 4
    # And a worker's own exception pickles back with its attributes.
    future = client.submit(lambda model: model.simulate(method="rk4", dt=0.5), m, pure=False)
    with pytest.raises(eomgen.IntegrationError) as remote:
        future.result(timeout=120)
    assert remote.value.t == info.value.t and remote.value.solution is not None


def test_a_process_pool_gives_the_same_bits():
    m = eomgen.load("double_pendulum")
    states = monte_carlo_states(m, 40)
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        batch = eomgen.sweep.run(pool, m, initial_states=states, t_end=2.0, t_out=[1.0, 2.0])
    local = m.simulate_many(initial_states=states, t_end=2.0, t_out=[1.0, 2.0])
    assert np.array_equal(batch.y, local.y)
    assert pickle.loads(pickle.dumps(m)) == m
