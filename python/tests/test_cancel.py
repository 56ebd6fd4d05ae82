"""Ctrl-C stops a long call: the work runs with the GIL released, and the
library asks between its steps whether to stop; the Python layer runs the
signal handlers then (at most every 50 ms), so SIGINT raises
KeyboardInterrupt within a fraction of a second, with or without a
progress callback."""

import os
import signal
import threading
import time

import pytest

import aeromag

# Most time from the signal to KeyboardInterrupt reaching the caller.
MAX_LATENCY_S = 1.5


def interrupted_after(delay_s, call):
    """Run `call()` with SIGINT sent to the process after `delay_s`; the
    seconds from the signal to KeyboardInterrupt."""
    sent = []

    def send():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(delay_s, send)
    try:
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            call()
        stopped = time.perf_counter()
    finally:
        timer.cancel()
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert sent, "the call returned before the signal was sent"
    return stopped - sent[0]


def test_ctrl_c_stops_gridding_promptly(survey_csv):
    survey = aeromag.read_flight(survey_csv)
    # A 10 m cell: minimum curvature sweeps for about 10 s without Ctrl-C.
    latency = interrupted_after(0.5, lambda: aeromag.grid_flight(survey, cell=10.0))
    print(f"grid_flight: KeyboardInterrupt {latency * 1000:.0f} ms after SIGINT")
    assert latency < MAX_LATENCY_S
    # The next call runs as usual.
    g = aeromag.grid_flight(survey, column="true_anomaly", cell=200.0)
    assert g.values.size > 0


def test_ctrl_c_stops_a_kalman_fit_with_a_progress_callback(cal):
    stages = []
    model = aeromag.TollesLawson(method="kalman")
    latency = interrupted_after(
        0.3, lambda: model.fit(cal, progress=lambda stage, done, total: stages.append(stage))
    )
    print(f"Kalman fit: KeyboardInterrupt {latency * 1000:.0f} ms after SIGINT")
    assert latency < MAX_LATENCY_S
    assert stages
