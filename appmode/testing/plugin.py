"""The pytest plugin (entry point `pytest11`, loaded wherever appmode is installed).

Fixtures:

- `appmode_board`: a simulated board served on two pseudo-terminals for the test
  (options from `@pytest.mark.appmode_board(profile=…, drive=…, faults=…, pace=…,
  flash=…)`), stopped after it;
- `appmode_board_factory`: `appmode_board_factory(**options)` makes more;
- `appmode_sim_url`: an in-process `sim://` URL (same options), for code that takes a
  pyserial URL;
- `appmode_ble_board`: the simulated board as a Bluetooth module behind the BlueZ
  stand-in (`.ble`, `.spp`: the URLs; `.bus`), with DBUS_SYSTEM_BUS_ADDRESS set to its
  bus for the test, so bleak and `ble://`/`bt://` reach it (Linux, dbus-daemon).

`--appmode-board URL` (and `--appmode-board2 URL` for its control port) runs the same
tests against a real car: the fixtures give its URLs, and a test that needs what only
the simulated board has (its state, its recording, a restart, faults) is skipped saying
so. The URLs are checked once, before any test (one line if one does not open), and at
every such test's teardown, passed or failed, the plugin sends the car its stop
(`stop_again` of the marker's profile on the APP port: an open frame closed, a rotation
ended, `Z`; the zero velocity frame on the control port). Nothing heavy is imported
until a fixture is used.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import urlencode

import pytest

if TYPE_CHECKING:
    from appmode.protocol.transcript import Transcript
    from appmode.testing.served import BoardState, ServedBoard

OPTIONS = ("profile", "drive", "faults", "pace", "flash")
"""What the `appmode_board` marker and the factory take."""
MARKER = (
    "appmode_board(profile='sheet', drive=None, faults='', pace=True, flash=None): the "
    "simulated board of the appmode_board and appmode_sim_url fixtures — its profile "
    "(sheet, minibalance, balance or a profile file), drive type (omni, mecanum, diff, "
    "diff-gyro), a faulty link "
    "('drop:0.01,corrupt:0.01'), pacing at the real line rates, and a flash file"
)
_SHARES = itertools.count(1)


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("appmode", "appmode's simulated robot-car board")
    group.addoption(
        "--appmode-board",
        metavar="URL",
        help="run the appmode_board tests against this real board's APP port (a device "
        "such as /dev/rfcomm0, or a pyserial URL) instead of the simulated board",
    )
    group.addoption(
        "--appmode-board2",
        metavar="URL",
        help="with --appmode-board: the real board's control port (UART2)",
    )
    group.addoption(
        "--appmode-chassis",
        metavar="URL",
        help="with --appmode-board: the real WHEELTEC board's chassis port "
        "(/dev/wheeltec_controller)",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", MARKER)
    for option in ("--appmode-board", "--appmode-board2", "--appmode-chassis"):
        url = config.getoption(option)
        if url is not None:
            _check_url(option, url)


def _check_url(option: str, url: str) -> None:
    """A real board's URL opens (else one line, and no test runs)."""
    target = None
    if not url.strip():
        raise pytest.UsageError(f"{option} is empty: give the board's device or URL")
    from appmode.errors import AppmodeError
    from appmode.ports.target import as_target
    from appmode.ports.urls import open_link

    try:
        target = as_target(url)  # its url shows no key
        open_link(target).close()
    except AppmodeError as exc:
        raise pytest.UsageError(
            f"{option} {url if target is None else target.url}: {exc}"
        ) from None


def _stop_real(board: RealBoard, profile: str | None) -> None:
    """Send a real car its stop, whatever the test left (it may have failed mid-drive)."""
    from appmode.board.profiles import profile_named
    from appmode.errors import AppmodeError
    from appmode.line.wire import CHASSIS_BAUD, UART2_BAUD
    from appmode.ports.urls import BAUD, open_link
    from appmode.protocol import chassis, control
    from appmode.protocol.session_end import stop_again

    try:
        steer_in_frames = profile_named(profile or "sheet").steer_in_frames
    except AppmodeError:
        steer_in_frames = False  # the marker's mistake is said where it is used
    stops = [(board.port, stop_again(frames_take_letters=not steer_in_frames), BAUD)]
    if board.uart2_url is not None:  # twice: the second is whole whatever half-frame was left
        stops.append((board.uart2_url, control.STOP * 2, UART2_BAUD))
    if board.chassis_url is not None:  # a chassis may never stop by itself: its zero frame
        stops.append((board.chassis_url, chassis.STOP, CHASSIS_BAUD))
    for url, stop, baud in stops:
        try:
            link = open_link(url, baud=baud)
            try:
                link.write(stop)
                link.flush()
            finally:
                link.close()
        except (AppmodeError, OSError) as exc:
            pytest.fail(f"appmode_board: could not stop the car at {url}: {exc}", pytrace=False)


def _options(request: pytest.FixtureRequest) -> dict[str, Any]:
    marker = request.node.get_closest_marker("appmode_board")
    if marker is None:
        return {}
    if marker.args:
        pytest.fail(
            f"@pytest.mark.appmode_board takes names ({', '.join(OPTIONS)}), not {marker.args!r}",
            pytrace=False,
        )
    return dict(marker.kwargs)


def _check_options(options: dict[str, Any]) -> None:
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        pytest.fail(
            f"appmode_board: unknown option {', '.join(unknown)} (it takes {', '.join(OPTIONS)})",
            pytrace=False,
        )


class RealBoard:
    """A real board given by --appmode-board: its URLs; the rest skips the test."""

    def __init__(self, port: str, uart2: str | None, chassis: str | None = None) -> None:
        self.port = port
        self.uart2_url = uart2
        self.chassis_url = chassis

    @property
    def uart2(self) -> str:
        if self.uart2_url is None:
            pytest.skip("the test uses the control port (UART2): give --appmode-board2 URL")
        return self.uart2_url

    @property
    def chassis(self) -> str:
        if self.chassis_url is None:
            pytest.skip("the test uses the chassis port: give --appmode-chassis URL")
        return self.chassis_url

    @staticmethod
    def _only_simulated(what: str) -> Any:
        pytest.skip(f"{what} is known only of the simulated board, not of --appmode-board")

    @property
    def state(self) -> BoardState:
        return self._only_simulated("the board's state")  # type: ignore[no-any-return]

    def wait_until(self, *args: Any, **kwargs: Any) -> BoardState:
        return self._only_simulated("the board's state")  # type: ignore[no-any-return]

    def recording(self) -> Transcript:
        return self._only_simulated("the board's recording")  # type: ignore[no-any-return]

    def restart(self) -> None:
        self._only_simulated("a restart (power cycle)")

    def assert_conforms(self, expected: str | Path) -> None:
        self._only_simulated("the board's recording")


def _real(config: pytest.Config, options: dict[str, Any]) -> RealBoard | None:
    url = config.getoption("--appmode-board")
    if url is None:
        return None
    for name in ("faults", "flash", "drive"):
        if options.get(name):
            pytest.skip(f"{name}= is for the simulated board; --appmode-board is a real one")
    config_of = config.getoption
    return RealBoard(url, config_of("--appmode-board2"), config_of("--appmode-chassis"))


@pytest.fixture
def appmode_board_factory(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[Callable[..., ServedBoard | RealBoard]]:
    """`make(profile=…, drive=…, faults=…, pace=…, flash=…)`: a new simulated board on two
    ptys, stopped when the test ends."""
    boards: list[ServedBoard] = []
    real_boards: list[tuple[RealBoard, str | None]] = []
    home = Path(request.path).parent

    def make(**options: Any) -> ServedBoard | RealBoard:
        _check_options(options)
        real = _real(request.config, options)
        if real is not None:
            real_boards.append((real, options.get("profile")))
            return real
        from appmode.errors import AppmodeError
        from appmode.testing.served import ServedBoard

        folder = tmp_path_factory.mktemp("appmode_board")
        failed = None
        try:
            board = ServedBoard(folder, home=home, **options)
        except AppmodeError as exc:
            failed = str(exc).removeprefix("appmode_board: ")
        if failed is not None:  # outside the except: one line, not two exceptions
            pytest.fail(f"appmode_board: {failed}", pytrace=False)
        boards.append(board)
        return board

    yield make
    for real_board, profile in real_boards:
        _stop_real(real_board, profile)
    failures = []
    for board in boards:
        try:
            board.close()
        except Exception as exc:  # a board that failed while serving fails the test
            failures.append(str(exc))
    if failures:
        pytest.fail("; ".join(failures), pytrace=False)


@pytest.fixture
def appmode_board(
    request: pytest.FixtureRequest, appmode_board_factory: Callable[..., ServedBoard | RealBoard]
) -> ServedBoard | RealBoard:
    """A simulated board served on two ptys for this test: `.port` (APP port, 9600 bps),
    `.uart2` (control port, 115200 bps), `.chassis` (a WHEELTEC profile's chassis port,
    on a third), `.recording()`, `.state`, `.wait_until(…)`,
    `.restart()`, `.assert_conforms(path)`; options by `@pytest.mark.appmode_board`."""
    return appmode_board_factory(**_options(request))


@pytest.fixture
def appmode_sim_url(request: pytest.FixtureRequest) -> Iterator[str]:
    """`sim://?…&share=NAME`: the simulated board in-process, for code that opens a pyserial
    URL (`serial.serial_for_url`); add `&port=uart2` for the same board's control port.
    Options by `@pytest.mark.appmode_board`; with --appmode-board, that board's URL (and
    the car's stop at the teardown)."""
    options = _options(request)
    _check_options(options)
    real = _real(request.config, options)
    if real is not None:
        yield real.port
        _stop_real(real, options.get("profile"))
        return
    import appmode.ports.urls  # noqa: F401 - registers sim:// with pyserial

    query = {k: v for k, v in options.items() if v not in (None, "")}
    if "pace" in query:
        query["pace"] = int(bool(query["pace"]))
    query["share"] = f"pytest-{next(_SHARES)}"
    yield f"sim://?{urlencode(query)}"


@pytest.fixture
def appmode_ble_board(
    request: pytest.FixtureRequest,
    tmp_path_factory: pytest.TempPathFactory,
    monkeypatch: pytest.MonkeyPatch,
) -> Iterator[ServedBoard]:
    """The simulated board as a Bluetooth module (BLE HC-08 and paired classic HC-05)
    behind the BlueZ stand-in on a private bus: `.ble` and `.spp` are the URLs that reach
    it, `.bus` the bus, which DBUS_SYSTEM_BUS_ADDRESS names for the test; the rest as
    `appmode_board` (options by `@pytest.mark.appmode_board`, faults excepted)."""
    from appmode.errors import AppmodeError
    from appmode.testing.served import ServedBoard

    options = _options(request)
    _check_options(options)
    failed = None
    try:
        board = ServedBoard(
            tmp_path_factory.mktemp("appmode_ble_board"),
            home=Path(request.path).parent,
            bluetooth=True,
            **options,
        )
    except AppmodeError as exc:
        failed = str(exc)
    if failed is not None:
        pytest.fail(f"appmode_ble_board: {failed}", pytrace=False)
    assert board.bus is not None
    monkeypatch.setenv("DBUS_SYSTEM_BUS_ADDRESS", board.bus)
    yield board
    board.close()
