"""The GIL is released while atelier works (another Python thread makes progress during
`Simulation.step()` and `atelier.run()`), and a Rust panic is raised as AtelierError with the
interpreter going on."""

import threading
import time

import pytest

import atelier
from conftest import FABRICS, SCENARIOS


class Counter:
    """A pure-Python busy loop in its own thread: it can only count while it holds the GIL."""

    def __init__(self):
        self.count = 0
        self.stop = False
        self.thread = threading.Thread(target=self._spin, daemon=True)

    def _spin(self):
        while not self.stop:
            self.count += 1

    def __enter__(self):
        self.thread.start()
        time.sleep(0.05)
        return self

    def __exit__(self, *exc):
        self.stop = True
        self.thread.join()


def counted_during(call):
    """How far the counting thread got while `call()` ran in this thread, and how long it ran.
    Had `call` kept the GIL, the counter would stand still until it returned (a thread waiting
    for the GIL gets it only when the holder releases it, which Rust code never does by
    itself)."""
    with Counter() as c:
        before, clock = c.count, time.perf_counter()
        call()
        return c.count - before, time.perf_counter() - clock


def test_step_releases_the_gil():
    sim = atelier.Simulation(str(SCENARIOS / "skirt_sewn.ron"))
    sim.step()  # the first step builds the solver's structures
    counted, seconds = counted_during(sim.step)
    assert seconds > 0.02, "a skirt step takes tens of milliseconds"
    assert counted > 10_000, f"the other thread counted {counted} in {seconds:.3f} s"


def test_run_releases_the_gil(tmp_path):
    scenario = str(SCENARIOS / "kes_bending_cotton_broad.ron")
    counted, seconds = counted_during(lambda: atelier.run(scenario, str(tmp_path)))
    assert seconds > 0.02
    assert counted > 10_000, f"the other thread counted {counted} in {seconds:.3f} s"


def test_tests_release_the_gil():
    silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
    counted, seconds = counted_during(lambda: atelier.drape(silk, "jis", max_time=0.05))
    assert counted > 10_000, f"the other thread counted {counted} in {seconds:.3f} s"


def test_two_threads_step_two_simulations():
    """Simulations are independent objects: two threads step two at once."""
    sims = [atelier.Simulation(str(SCENARIOS / "skirt_sewn.ron")) for _ in range(2)]
    threads = [threading.Thread(target=s.advance, args=(0.02,)) for s in sims]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [s.report()["steps"] for s in sims] == [2, 2]
    assert (sims[0].positions == sims[1].positions).all()


def test_a_panic_is_an_atelier_error_and_the_interpreter_goes_on():
    """No input of the public API was found that panics (docs/python.md lists what was tried),
    so the hidden `_panic_for_test` panics where a bug would: inside a call that runs without
    the GIL. It is raised as AtelierError (an Exception, which `except Exception` and notebooks
    catch), not pyo3's PanicException (a BaseException)."""
    with pytest.raises(atelier.AtelierError, match="internal error.*a Rust panic.*boom") as info:
        atelier._atelier._panic_for_test("boom")
    assert isinstance(info.value, Exception)
    try:
        atelier._atelier._panic_for_test("again")
    except Exception as e:  # what a notebook cell does
        caught = e
    assert isinstance(caught, atelier.AtelierError)
    # The interpreter and the module go on.
    silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
    assert silk.tensile_loop("warp").shape == (201, 2)
    assert sum(range(10)) == 45


class Stop(Exception):
    pass


def test_a_signal_stops_a_long_call(tmp_path):
    """Python's signal handlers run every 0.2 s while `drape()` and `Simulation.advance()`
    work without the GIL: Ctrl-C's handler (here one raising `Stop`, so that pytest's own
    KeyboardInterrupt handling stays out of it) stops them, and the objects stay usable."""
    import os
    import signal

    def handler(signum, frame):
        raise Stop()

    previous = signal.signal(signal.SIGINT, handler)
    try:
        silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
        threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
        clock = time.perf_counter()
        with pytest.raises(Stop):
            atelier.drape(silk, "thesis", max_time=6.0)  # about 20 s uninterrupted
        assert time.perf_counter() - clock < 5.0
        sim = atelier.Simulation(str(SCENARIOS / "skirt_sewn.ron"))
        threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
        with pytest.raises(Stop):
            sim.advance()  # about 20 s uninterrupted
        steps = sim.report()["steps"]
        assert 0 < steps < 117
        assert sim.step()["time_s"] == pytest.approx(0.01 * (steps + 1))
    finally:
        signal.signal(signal.SIGINT, previous)
