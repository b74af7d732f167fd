"""The pytest plugin, used as our users use it: from test files of their own, in folders
of their own, run by pytest in a process of their own (and here, from this suite too)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial

from appmode.errors import AppmodeError
from appmode.testing.served import ServedBoard
from tests.support.processes import ROOT

EXAMPLE = ROOT / "examples" / "pytest_host"


def pytest_in(folder: Path, *args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """`pytest ARGS` run in `folder`, as a user runs it: no conftest, no appmode import.
    Its temporary folders are its own (pytest would clean ours, its elders, away)."""
    basetemp = f"--basetemp={folder / 'pytest-tmp'}"
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-rs", basetemp, *args],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """The example project copied to a folder of its own, beside no pyproject of ours."""
    folder = tmp_path / "project"
    shutil.copytree(EXAMPLE, folder, ignore=shutil.ignore_patterns("__pycache__"))
    (folder / "pytest.ini").write_text("[pytest]\n")  # its own rootdir, not ours
    return folder


def test_the_example_project_passes_with_plain_pytest(project: Path) -> None:
    assert "import appmode" not in (project / "test_carhost.py").read_text()
    done = pytest_in(project)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "4 passed" in done.stdout


def test_the_example_project_passes_on_two_workers(project: Path) -> None:
    done = pytest_in(project, "-n", "2")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 workers" in done.stdout and "4 passed" in done.stdout


def test_a_recording_that_does_not_conform_fails_with_the_runners_message(
    tmp_path: Path,
) -> None:
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "fast.transcript").write_text(
        "# appmode transcript v1\n0.000 > J\n0.000 > A\n0.600 < {A0:900..1000:0:0}$\n"
    )
    (tmp_path / "test_fast.py").write_text(
        "import serial, time\n\n"
        "def test_fast(appmode_board):\n"
        "    with serial.Serial(appmode_board.port, 9600) as port:\n"
        "        port.write(b'JA')\n"
        "        time.sleep(1.5)\n"
        "        port.write(b'Z')\n"
        "    appmode_board.assert_conforms('fast.transcript')\n"
    )
    done = pytest_in(tmp_path)
    assert done.returncode == 1
    assert "1 failed" in done.stdout
    assert "fast.transcript:4: expected {A0:900..1000:0:0}$ at " in done.stdout
    assert re.search(r"nothing matched by 1\.\d+ s; got \{A0:4\d\d:0:0\}\$ at ", done.stdout)


def test_a_real_board_runs_what_it_can_and_skips_the_rest_saying_why(tmp_path: Path) -> None:
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_car.py").write_text(
        "import serial\n\n"
        "def test_records(appmode_board):\n"
        "    with serial.serial_for_url(appmode_board.port, 9600, timeout=1) as port:\n"
        "        port.write(b'{Q:P}')\n"
        "        assert b'{C' in port.read_until(b'{C', 400)\n\n"
        "def test_state(appmode_board):\n"
        "    assert appmode_board.state.velocity == (0, 0, 0)\n\n"
        "def test_uart2(appmode_board):\n"
        "    assert appmode_board.uart2\n\n"
        "def test_url(appmode_sim_url):\n"
        "    assert not appmode_sim_url.startswith('sim://')\n"
    )
    with ServedBoard(tmp_path / "car") as car:  # the "real" car, served on a pty
        done = pytest_in(tmp_path, "--appmode-board", car.port)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 passed, 2 skipped" in done.stdout
    assert "the board's state is known only of the simulated board" in done.stdout
    assert "give --appmode-board2 URL" in done.stdout


def test_the_plugin_names_its_options_in_pytest_help(tmp_path: Path) -> None:
    done = pytest_in(tmp_path, "--help")
    assert "--appmode-board=URL" in done.stdout
    markers = pytest_in(tmp_path, "--markers")
    assert "@pytest.mark.appmode_board(profile='sheet'" in markers.stdout


@pytest.mark.appmode_board(profile="minibalance")
def test_the_marker_picks_the_profile(appmode_board: ServedBoard) -> None:
    with serial.Serial(appmode_board.port, 9600, timeout=2) as port:
        text = port.read_until(b"mpu_set_sensor", 4000)  # the firmware's start-up text
    assert b"mpu_set_sensor" in text
    assert appmode_board.profile.name == "minibalance"
    assert "@board profile=minibalance" in appmode_board.transcript_path.read_text()


@pytest.mark.appmode_board(faults="drop:1")
def test_a_faulty_link_loses_what_it_says(appmode_board: ServedBoard) -> None:
    with serial.Serial(appmode_board.port, 9600, timeout=0.5) as port:
        port.write(b"JA")
        assert port.read(100) == b""  # every byte from the board is dropped
    time.sleep(0.3)
    state = appmode_board.state
    assert not state.moving and state.page == "direction"
    assert not [e for e in appmode_board.recording().entries if e.direction == ">"]


def test_a_restart_keeps_the_ports_and_what_was_saved(appmode_board: ServedBoard) -> None:
    with serial.Serial(appmode_board.port, 9600, timeout=1) as port:
        port.write(b"{0:800}{Q:W}{1:5000}")
        appmode_board.wait_until(lambda s: s.params["max_position"] == 5000, 2, "the sets")
        appmode_board.restart()
        assert appmode_board.state.time < 0.5
        port.reset_input_buffer()
        port.write(b"{Q:P}")
        assert b"{C800:10000:" in port.read_until(b"}$", 400) + port.read_until(b"}$", 400)


def test_the_state_follows_the_control_port(appmode_board: ServedBoard) -> None:
    assert appmode_board.state.driver == "app"
    with serial.Serial(appmode_board.uart2, 115200, timeout=1) as port:
        port.write(bytes.fromhex("FF FE 01 00 00 01 2C 00 00 00"))
        state = appmode_board.wait_until(lambda s: s.velocity[1] > 250, 3, "y above 250")
        assert state.driver == "uart2"
        port.write(bytes.fromhex("FF FE 01 00 00 00 00 00 00 00"))
        appmode_board.wait_until(lambda s: not s.moving, 3, "a standstill")


def test_appmode_sim_url_opens_both_ports_of_one_board(appmode_sim_url: str) -> None:
    with (
        serial.serial_for_url(appmode_sim_url, timeout=1) as app,
        serial.serial_for_url(appmode_sim_url + "&port=uart2", timeout=1) as uart2,
    ):
        uart2.write(bytes.fromhex("FF FE 80 80 11 00 00 00 00 00"))
        assert uart2.read(6) == bytes.fromhex("23 01 00 00 01 F4")
        app.write(b"{Q:P}")
        assert b"{C500:" in app.read_until(b"{C500:", 400)


def test_a_board_with_a_bad_option_says_what_it_takes(tmp_path: Path) -> None:
    with pytest.raises(AppmodeError, match="delay and split are sim:// only"):
        ServedBoard(tmp_path, faults="delay:0.1")
    with pytest.raises(AppmodeError, match="drive"):
        ServedBoard(tmp_path, drive="tank")
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_bad.py").write_text(
        "import pytest\n\n"
        "@pytest.mark.appmode_board(speed=3)\n"
        "def test_bad(appmode_board):\n"
        "    pass\n"
    )
    done = pytest_in(tmp_path)
    assert done.returncode == 1
    assert "appmode_board: unknown option speed (it takes profile, drive, faults" in done.stdout


def test_the_guide_s_example_passes(tmp_path: Path) -> None:
    """The example of docs/guide/pytest-plugin.md, as a user copies it."""
    section = (ROOT / "docs" / "guide" / "pytest-plugin.md").read_text()
    code = section[section.index("```python\n") + 10 : section.index("```\n", 10)]
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_readme_example.py").write_text(code)
    shutil.copy(EXAMPLE / "forward_then_stop.transcript", tmp_path)
    done = pytest_in(tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 passed" in done.stdout


def test_a_real_board_is_stopped_at_every_teardown_even_after_a_failure(
    tmp_path: Path,
) -> None:
    """Issue 49.4: a test that wrote `JA` and failed left the car at `{A0:500:0:0}$`."""
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_car.py").write_text(
        "import serial\n\n"
        "def test_drives_then_fails(appmode_board):\n"
        "    with serial.serial_for_url(appmode_board.port, 9600, timeout=1) as port:\n"
        "        port.write(b'JA')\n"
        "        port.flush()\n"
        "    assert False, 'the test failed mid-drive'\n"
    )
    with ServedBoard(tmp_path / "car") as car:  # the "real" car, served on a pty
        done = pytest_in(tmp_path, "--appmode-board", car.port)
        car.wait_until(lambda state: state.velocity == (0, 0, 0), timeout=5)
        sent = [e.data for e in car.recording().entries if e.direction == ">"]
    assert done.returncode == 1, done.stdout + done.stderr
    assert "the test failed mid-drive" in done.stdout
    assert b"".join(sent).endswith(b"A{}KJZ"), sent


@pytest.mark.parametrize("url", ["", "/dev/appmode-no-such-device"])
def test_a_board_url_that_does_not_open_is_one_line_before_any_test(
    tmp_path: Path, url: str
) -> None:
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_car.py").write_text("def test_it(appmode_board):\n    pass\n")
    done = pytest_in(tmp_path, "--appmode-board", url)
    assert done.returncode == 4, done.stdout + done.stderr
    [line] = [x for x in done.stderr.splitlines() if x.strip()]
    assert line.startswith("ERROR: --appmode-board "), line
    assert "Traceback" not in done.stdout + done.stderr


def test_a_bad_marker_fails_in_one_line(tmp_path: Path) -> None:
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_car.py").write_text(
        "import pytest\n\n"
        "@pytest.mark.appmode_board(profile='nosuch')\n"
        "def test_it(appmode_board):\n    pass\n"
    )
    done = pytest_in(tmp_path)
    assert done.returncode == 1, done.stdout
    assert "appmode_board: appmode_board:" not in done.stdout
    assert "During handling of the above exception" not in done.stdout
    assert "appmode_board: " in done.stdout


@pytest.mark.appmode_board(profile="wheeltec-diff")
def test_a_wheeltec_board_serves_its_chassis_port(appmode_board: ServedBoard) -> None:
    from appmode.protocol import chassis

    assert appmode_board.chassis is not None
    with serial.Serial(appmode_board.chassis, 115200, timeout=1) as port:
        data = port.read(3 * chassis.STATUS_LEN)
    frames = [e for e in chassis.StatusDecoder().feed(data) if isinstance(e, chassis.Status)]
    assert frames and frames[-1].flag_stop == 1, "booting: Flag_Stop"
    assert any(e.direction == "c<" for e in appmode_board.recording().entries)


def test_a_real_chassis_is_sent_its_zero_frame_at_every_teardown(tmp_path: Path) -> None:
    """A chassis may never stop by itself: the plugin ends a test with its zero frame."""
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    (tmp_path / "test_car.py").write_text(
        "import serial\n\n"
        "def test_drives_then_fails(appmode_board):\n"
        "    with serial.serial_for_url(appmode_board.chassis, 115200, timeout=1) as port:\n"
        "        port.write(bytes.fromhex('7B 00 00 01 2C 00 00 00 00 56 7D'))\n"
        "        port.flush()\n"
        "    assert False, 'the test failed mid-drive'\n"
    )
    with ServedBoard(tmp_path / "car", profile="wheeltec-mec") as car:
        assert car.chassis is not None
        done = pytest_in(tmp_path, "--appmode-board", car.port, "--appmode-chassis", car.chassis)
        time.sleep(0.3)
        sent = [e.text for e in car.recording().entries if e.direction == "c>"]
    assert done.returncode == 1, done.stdout + done.stderr
    assert sent[-1] == "7B 00 00 00 00 00 00 00 00 7B 7D", sent
