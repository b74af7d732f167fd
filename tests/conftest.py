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
    """`-n auto`: two workers a core on an idle machine, one a core on a busy one.

    Most tests wait on boards, ptys and processes in real time: on two cores the suite's
    processes kept 0.8 of them busy on average with four workers. Three workers took
    7 min 21 s, four 5 min 43 s to 6 min 16 s (the tests' own durations adding up to
    about 1,200 s each time). Five took 4 min 51 s to 5 min 10 s, but one run in ten
    failed a test that keeps time to ±25 ms, and six failed one in half their runs,
    even with the other tests' processes at nice 10 (which, beside two busy programs,
    all but stopped them). So two a core, and, as `make -l` does, a run started beside
    another run of this suite (RUNS), or on a machine whose cores are already busy,
    takes one worker a core."""
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
    """Tests of this suite that run at once on this machine, whatever the runs: two a
    core (`pytest_xdist_auto_num_workers`)."""
    return 2 * (os.cpu_count() or 1)


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
    within 0.35."""
    others = _other_runs()
    alone = item.get_closest_marker("alone") is not None
    timing = item.get_closest_marker("timing") is not None and bool(others)
    with _machine(alone, timing, others):
        yield


@contextlib.contextmanager
def _machine(alone: bool, timing: bool, others: list[str]) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # Windows: tests are not kept apart
        yield
        return
    run = _run()
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
            slots = [held.enter_context((SLOTS / f"{k}.lock").open("a")) for k in range(_slots())]
            _wait(
                lambda: any(_locked(slot.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB) for slot in slots)
            )
        yield
    # closing the files let the locks go


SLOTS = RUNS / "slots"
"""`K.lock` for K below `_slots()`: a test of any run holds one while it runs (taken last,
its run's locks held), so two runs side by side load the machine as one does. Beside a
second run (seven workers on two cores: five and two), boards and ptys starved in
real time: a send 235 ms late, a re-sent frame missing, a transcript's record late."""


def _wanted(run: str) -> bool:
    """Whether a test that wants the machine runs or waits to: an `alone` one of any
    run, a `timing` one of another run than `run`."""
    for path in ALONE.iterdir():
        owner, _, pid = path.stem.partition("-")
        mine = pid == str(os.getpid())
        wants = path.suffix == ".alone" or (path.suffix == ".wants" and owner != run)
        if wants and not mine and _running(pid, path):
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
    """The page's tests in Chromium go first and tests marked `alone` last: pytest-xdist
    hands the last out while the other workers are finishing, so the few tests that
    wait while one runs (pytest_runtest_protocol) are the run's last, and the browsers,
    whose heartbeats a burst of boards starves past the page's 0.25-s lease (a held
    direction then stops, as it must), are done long before (they came last by name).
    Within each, the long ones (`slow`) first: a long test handed out last keeps the
    run going after the rest."""
    items.sort(
        key=lambda item: (
            item.get_closest_marker("alone") is not None,
            not item.nodeid.startswith("tests/web/"),
            item.get_closest_marker("slow") is None,
        )
    )


@pytest.fixture(autouse=True)
def private_data_folder(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> Path:
    folder = tmp_path_factory.mktemp("data")
    monkeypatch.setenv("XDG_DATA_HOME", str(folder))
    return folder
