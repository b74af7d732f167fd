"""The replay benchmark's drift (bench/replay_timing.py): a schedule that slips is
caught whatever the load; a load that grows during a run is not called drift."""

from __future__ import annotations

import random

from bench.replay_timing import drift_ms_per_min, trend_ms_per_min

SPACING = 0.01
EVENTS = 10_000


def bursts(seed: int) -> list[float]:
    """Lateness (s) of a player keeping its deadlines on a machine that gets busier:
    a few events a second late by up to 90 ms, more of them as the run goes on."""
    rng = random.Random(seed)
    late = [rng.uniform(0.005, 0.09) if rng.random() < k / EVENTS / 5 else 0 for k in range(EVENTS)]
    return [x + rng.uniform(0, 0.00005) for x in late]


def test_a_load_that_grows_is_a_trend_not_a_drift() -> None:
    lateness = bursts(1)
    assert trend_ms_per_min(lateness, SPACING) > 1.0  # what the old figure called drift
    assert abs(drift_ms_per_min(lateness, SPACING)) < 0.01


def test_a_schedule_that_slips_is_drift_under_any_load() -> None:
    slip = 0.1e-3 / 60 * SPACING  # 0.1 ms a minute
    for base in (bursts(2), [0.0] * EVENTS):
        lateness = [x + k * slip for k, x in enumerate(base)]
        assert abs(drift_ms_per_min(lateness, SPACING) - 0.1) < 0.01


def test_a_player_that_waits_from_its_last_send_drifts() -> None:
    """Each wait measured from the last send: a late event delays every one after it."""
    rng = random.Random(3)
    lateness, behind = [], 0.0
    for _ in range(EVENTS):
        delay = rng.uniform(0.005, 0.02) if rng.random() < 0.01 else 0.0
        behind += delay + 20e-6  # and the player's own time for each event
        lateness.append(behind)
    assert drift_ms_per_min(lateness, SPACING) > 0.05
