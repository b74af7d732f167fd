"""Shared helpers live in tests/support/: decoders fed whole, split and byte by byte
(decoders.py), appmode run as a process and boards served by one (processes.py), and an
RFC 2217 server (rfc2217_server.py).

Every test runs with its own data folder: the console's history never touches the user's.
"""

from __future__ import annotations

import compileall
import contextlib
import os
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

import pytest

from tests.support.load import busy_cores


def pytest_configure(config: pytest.Config) -> None:
    """The package's bytecode, brought up to date once before the run (by the controller,
    not each worker): the suite starts appmode some 800 times, and where
    PYTHONDONTWRITEBYTECODE is set (as on this machine's image) each start compiled every
    module again, 0.12 s of its 0.4 s."""
    if not hasattr(config, "workerinput"):
        compileall.compile_dir(Path(__file__).parents[1] / "appmode", quiet=2)


RUNS = Path(tempfile.gettempdir()) / "appmode-test-runs"
"""A file per run of this suite in progress on the machine (its controller's pid)."""


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """`-n auto`: four workers a core on an idle machine, one a core on a busy one.

    Most tests wait on boards, ptys and processes in real time (ROS's and the share's
    take as long on an idle machine as in the suite): four workers on two cores kept
    0.8 of them busy, and took 5 min 43 s to 6 min 16 s. Eight took 4 min 21 s to
    4 min 39 s, their tests sharing places (`_places`): a test in Chromium takes two
    (the page's tests keep both cores busy for a minute), and beside a test marked
    `timing`, or another run, no more tests run than at two workers a core, the load
    their bounds were set for (five workers had failed one run in ten by ±25 ms, six
    half). As `make -l` does, a run started beside another run of this suite (RUNS), or
    on a machine whose cores are already busy, takes one worker a core."""
    cores = os.cpu_count() or 1
    mine = RUNS / str(os.getpid())
    try:
        RUNS.mkdir(exist_ok=True)
        mine.touch()
        config.add_cleanup(lambda: mine.unlink(missing_ok=True))
        others = [run for run in RUNS.iterdir() if run != mine and _running(run.name)]
    except OSError:  # another user's folder: the load average alone tells
        others = []
    return cores if others or busy_cores() >= 0.9 * cores else _slots()


def _slots() -> int:
    """Places for the tests of this suite that run at once on this machine, whatever the
    runs: four a core (`pytest_xdist_auto_num_workers`)."""
    return 4 * (os.cpu_count() or 1)


def _running(pid: str, path: Path | None = None) -> bool:
    """Whether the process of a file named by its pid (in RUNS unless `path`) is still
    going (a file left by a killed run is not, and goes)."""
    if not pid.isdigit() or os.name != "posix":  # os.kill(pid, 0) tests a pid on POSIX only
        return False
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        (path or RUNS / pid).unlink(missing_ok=True)
        return False
    except OSError:  # another user's: running
        return True
    return True


ALONE = RUNS / "alone"
"""Per run of the suite: `RUN.lock`, which its tests hold shared and a test that wants
the machine exclusively, and `RUN-PID.wants` (beside other runs: a `timing` test) or
`RUN-PID.alone` (an `alone` test), such a test (its worker's pid) running or waiting
to."""
ALONE_WAIT = 300.0
"""Seconds a test waits for the machine before it runs anyway."""


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item) -> Iterator[None]:
    """A test marked `alone` (the suite in real time, run last) has the machine to
    itself: it waits until the tests running in this run and in others beside it end,
    and theirs wait until it has. One marked `timing` has it to itself across runs of
    this suite side by side, its own run going on beside it (the load its bounds were
    set for). In the real-time suite beside the run's last tests a board's encoder
    report came 50 ms late (±25 ms); beside another run its boards applied commands
    later than its ±0.3 s, and a console let go of stopped the car 0.45 s after, not
    within 0.35. A test in Chromium takes two places: a browser drawing a page keeps a
    core busy (six of them kept both cores busy for a minute)."""
    others = _other_runs()
    alone = item.get_closest_marker("alone") is not None
    timing = item.get_closest_marker("timing") is not None
    places = 2 if "browser" in getattr(item, "fixturenames", ()) else 1
    with _machine(alone, timing, others, places):
        yield


@contextlib.contextmanager
def _machine(alone: bool, timing: bool, others: list[str], places: int) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # Windows: tests are not kept apart
        yield
        return
    run = _run()
    kept = timing
    timing = timing and bool(others)  # beside other runs: the machine to itself
    with contextlib.ExitStack() as held:
        try:
            ALONE.mkdir(parents=True, exist_ok=True)
            if alone or timing:
                wants = ALONE / f"{run}-{os.getpid()}.{'alone' if alone else 'wants'}"
                wants.touch()
                held.callback(wants.unlink, missing_ok=True)
                runs = [*others, run] if alone else others
                locks = [held.enter_context((ALONE / f"{o}.lock").open("a")) for o in runs]
            else:
                _wait(lambda: not _wanted(run))  # such a test goes first
                locks = [held.enter_context((ALONE / f"{run}.lock").open("a"))]
        except OSError:  # another user's folder
            locks = []
        kind = fcntl.LOCK_EX if alone or timing else fcntl.LOCK_SH
        for lock in locks:
            _wait(lambda lock=lock: _locked(lock.fileno(), kind | fcntl.LOCK_NB))
        with contextlib.suppress(OSError):  # another user's folder
            SLOTS.mkdir(exist_ok=True)
            held.enter_context(_places(places, kept, bool(others)))
        yield
    # closing the files let the locks go


SLOTS = RUNS / "slots"
"""`K.lock` for K below `_slots()`: a test of any run holds one while it runs (a test in
Chromium two; taken last, its run's locks held), so two runs side by side load the
machine as one does. Beside a second run (seven workers on two cores: five and two),
boards and ptys starved in real time: a send 235 ms late, a re-sent frame missing, a
transcript's record late. A `timing` test holds `timing.lock` shared while it waits and
runs, and the last two places a core shared with the other timing tests (`_places`).
`gate.lock` is held by the test taking its places, so that two tests each holding some
of the places they want never wait for each other."""


@contextlib.contextmanager
def _places(wanted: int, timing: bool, crowded: bool) -> Iterator[None]:
    """`wanted` of the places in SLOTS, held until the end of the block. While a `timing`
    test runs or waits, or another run goes on beside this one (`crowded`), tests take
    the first two places a core only: a timing test holds the others, shared with the
    other timing tests, once the tests that had them have ended, so that beside it run
    no more tests than two workers a core ran (four on two cores)."""
    import fcntl

    nb = fcntl.LOCK_NB
    with contextlib.ExitStack() as files:
        slots = [files.enter_context((SLOTS / f"{k}.lock").open("a")) for k in range(_slots())]
        first, kept = slots[: 2 * (os.cpu_count() or 1)], slots[2 * (os.cpu_count() or 1) :]
        timings = files.enter_context((SLOTS / "timing.lock").open("a"))
        if timing:
            _wait(lambda: _locked(timings.fileno(), fcntl.LOCK_SH | nb))
            _wait(lambda: all(_locked(slot.fileno(), fcntl.LOCK_SH | nb) for slot in kept))
        taken: list[IO[str]] = []

        def enough() -> bool:
            few = timing or crowded or not _locked(timings.fileno(), fcntl.LOCK_EX | nb)
            if not few:  # no timing test runs or waits: the kept places are free
                fcntl.flock(timings.fileno(), fcntl.LOCK_UN)
            free = first if few else slots
            for slot in free:
                if (
                    len(taken) < wanted
                    and slot not in taken
                    and _locked(slot.fileno(), fcntl.LOCK_EX | nb)
                ):
                    taken.append(slot)
            return len(taken) >= wanted

        with (SLOTS / "gate.lock").open("a") as gate:
            _wait(lambda: _locked(gate.fileno(), fcntl.LOCK_EX | nb))
            _wait(enough)
        yield


def _wanted(run: str) -> bool:
    """Whether a test of another run than `run` that wants the machine (`alone` or
    `timing`) runs or waits to: it goes before this run's next tests. This run's own
    `alone` tests wait for its other tests instead, which workers still held (two each)
    when they were handed out."""
    for path in ALONE.iterdir():
        owner, _, pid = path.stem.partition("-")
        wants = owner != run and path.suffix in (".alone", ".wants")
        if wants and _running(pid, path):
            return True
    return False


def pytest_unconfigure(config: pytest.Config) -> None:
    """The run's lock file goes with it (its controller's)."""
    if not hasattr(config, "workerinput"):
        (ALONE / f"{os.getpid()}.lock").unlink(missing_ok=True)


def _locked(fd: int, how: int) -> bool:
    import fcntl

    try:
        fcntl.flock(fd, how)
    except BlockingIOError:
        return False
    return True


def _wait(done: Callable[[], bool]) -> None:
    end = time.monotonic() + ALONE_WAIT
    while not done() and time.monotonic() < end:
        time.sleep(0.05)


def _run() -> str:
    """This run's name in RUNS: its controller's pid (a worker's parent)."""
    return str(os.getppid() if os.environ.get("PYTEST_XDIST_WORKER") else os.getpid())


def _other_runs() -> list[str]:
    """The other runs of this suite going on the machine."""
    mine = _run()
    try:
        return [path.name for path in RUNS.iterdir() if path.name != mine and _running(path.name)]
    except OSError:
        return []


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The tests marked `timing` go first, then the page's tests in Chromium, and tests
    marked `alone` last. The timing tests, which keep half the places while they run
    (`_places`), then run together (among the others, they held a run at four tests for
    100 s); the browsers, whose heartbeats a burst of boards starves past the page's
    0.25-s lease (a held direction then stops, as it must), are done long before the
    burst (they came last by name); and the few tests that wait while an alone one runs
    (pytest_runtest_protocol) are the run's last. Within each, the long ones (`slow`)
    first: a long test handed out last keeps the run going after the rest."""
    items.sort(key=_order)


def _order(item: pytest.Item) -> tuple[bool, bool, bool, bool]:
    """pytest_collection_modifyitems' key: alone last; timing first; then the page's."""
    alone, timing, slow = (
        item.get_closest_marker(m) is not None for m in ("alone", "timing", "slow")
    )
    page = item.nodeid.startswith("tests/web/")
    return alone, not timing, not (timing or page), not slow


@pytest.fixture(autouse=True)
def private_data_folder(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> Path:
    folder = tmp_path_factory.mktemp("data")
    monkeypatch.setenv("XDG_DATA_HOME", str(folder))
    return folder
