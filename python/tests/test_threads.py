"""Threads: two Simulations on two Python threads, one solver thread each,
run in parallel (the interpreter lock is released while the solver steps):
at most 0.6 times the wall time of running them one after the other, and
with the same bits. The figure goes in BENCHMARKS.md ("Python: two runs on
two threads"); `python python/tests/test_threads.py` prints it."""

import os
import subprocess
import sys
import threading
import time

import pytest

import meshless_impact as mi

# A Taylor run of about a second on one thread (test 7 at 7 across to 40 us).
CASE = {"particles_radial": 7, "end_time": 4e-5}
BOUND = 0.6


def one(results, k, speed):
    sim = mi.Simulation("taylor", threads=1, impact_speed=speed, **CASE)
    sim.run()
    results[k] = sim.observables()


def measure():
    """(sequential wall time, threaded wall time, the two runs' results)."""
    seq, par = [None, None], [None, None]
    t0 = time.perf_counter()
    one(seq, 0, 181.0)
    one(seq, 1, 200.0)
    t1 = time.perf_counter()
    threads = [threading.Thread(target=one, args=(par, k, v)) for k, v in enumerate((181.0, 200.0))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    t2 = time.perf_counter()
    assert par == seq, "the same bits on threads"
    return t1 - t0, t2 - t1


def test_the_interpreter_runs_while_a_simulation_steps():
    """While a run steps on one thread, Python code runs on another: the
    lock is released (whatever the load on the machine)."""
    sim = mi.Simulation("taylor", threads=1, **CASE)
    done = threading.Event()
    ticks = 0

    def run():
        sim.run()
        done.set()

    t = threading.Thread(target=run)
    start = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks += 1
    t.join()
    assert sim.finished and ticks > 1000 * (time.perf_counter() - start), ticks


SPIN = "import time\nt = time.perf_counter()\nn = 0\nwhile time.perf_counter() - t < 0.5:\n    n += 1\nprint(n)"


def free_cores():
    """About how many cores this process can have now: the work of two
    processes spinning at once over that of one alone (the machine may be
    shared with other jobs)."""
    def spin(k):
        ps = [subprocess.Popen([sys.executable, "-c", SPIN], stdout=subprocess.PIPE, text=True) for _ in range(k)]
        return sum(int(p.communicate()[0]) for p in ps)
    return spin(2) / spin(1)


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores")
def test_two_simulations_on_two_threads_overlap():
    # On a machine shared with other jobs two cores may not be free: the
    # bound is checked only where two processes get about two cores' work
    # done (the test above checks the lock's release on any machine); the
    # best of up to five tries is held to it.
    cores = free_cores()
    if cores < 1.7:
        pytest.skip(f"about {cores:.2f} cores free (other jobs): the overlap needs two")
    ratios = []
    for _ in range(5):
        seq, par = measure()
        ratios.append(par / seq)
        if ratios[-1] <= BOUND:
            break
    assert min(ratios) <= BOUND, f"threaded / sequential wall time: {ratios}"


if __name__ == "__main__":
    print(f"about {free_cores():.2f} cores free")
    for _ in range(5):
        seq, par = measure()
        print(f"sequential {seq:.3f} s, two threads {par:.3f} s, ratio {par / seq:.3f}")
