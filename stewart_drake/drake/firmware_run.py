"""Running a closed loop whose tick is the user's own C firmware (``simulate --firmware``) in a child
process (``system.isolate``): a hang, an ``exit()`` or a crash in their code is one line naming the file, and
their ``printf`` cannot reach our output. Only user-supplied firmware runs this way: the generated
firmware (the default C engine) runs in this process, at full speed.

The child reports progress while the simulated time advances (checked every second), so the time limit
is on the firmware making no progress, not on the length of the run.
"""

from __future__ import annotations

import threading

from stewart_drake.drake.simulation import Scenario, build_simulation
from stewart_drake.system.isolate import run_isolated

WATCH_PERIOD_S = 1.0


def run_closed_loop(scenario: Scenario, duration: float, progress: bool) -> tuple:
    """``(SimulationLog, max constraint gap m)`` of ``scenario`` run for ``duration`` s, in this process."""
    sim = build_simulation(scenario)
    log = sim.run(duration, progress=progress)
    return log, sim.max_constraint_gap(), sim.tick_loop


def run_user_firmware(scenario: Scenario, duration: float, progress: bool, path: str, limit: float) -> tuple:
    """``run_closed_loop`` in a child process, stopped when the simulated time has not advanced for
    ``limit`` seconds (building, i.e. compiling and loading the firmware, included): ``(log, the largest
    constraint gap (m), Simulation.tick_loop)``."""
    return run_isolated(_in_child, scenario, duration, progress, path=path, limit=limit)


def _in_child(beat, scenario: Scenario, duration: float, progress: bool) -> tuple:
    sim = build_simulation(scenario)  # compiles and loads the user's file (a constructor runs here)
    beat()
    stop = threading.Event()

    def watch() -> None:  # cffi releases the GIL inside the C tick: this runs while the firmware does
        last = sim.simulator.get_context().get_time()
        while not stop.wait(WATCH_PERIOD_S):
            now = sim.simulator.get_context().get_time()
            if now > last:
                last = now
                beat()

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    try:
        log = sim.run(duration, progress=progress)
    finally:
        stop.set()
        watcher.join()
    return log, sim.max_constraint_gap(), sim.tick_loop
