"""Tests of carhost.py against appmode's simulated board: `pytest` in this folder.

The fixtures come from appmode's pytest plugin, installed with appmode: nothing here
imports appmode. `pytest --appmode-board /dev/rfcomm0` runs the same tests against a
real car; those that look inside the board are then skipped, saying why.
"""

from __future__ import annotations

import pytest
from carhost import AppPort, ControlPort


def test_forward_drives_and_stop_stops(appmode_board):
    car = AppPort(appmode_board.port)
    car.forward()
    moving = [f for letter, f in car.records(1.0) if letter == "A" and f[1] > 0]
    assert moving, "no A record showed the car moving forward"
    car.stop()
    appmode_board.wait_until(lambda s: not s.moving, timeout=2, what="a standstill")
    car.close()
    # what the board saw and sent, line by line: forward then stop, A records rising
    appmode_board.assert_conforms("forward_then_stop.transcript")


def test_a_parameter_set_shows_in_the_c_record(appmode_board):
    car = AppPort(appmode_board.port)
    car.set_param(0, 800)  # max_speed
    assert car.read_params()[0] == 800
    assert appmode_board.state.params["max_speed"] == 800
    car.close()
    received = [e.text for e in appmode_board.recording().entries if e.direction == "<"]
    assert any(text.startswith("{C800:") for text in received)


def test_a_saved_parameter_survives_a_restart(appmode_board):
    car = AppPort(appmode_board.port)
    car.set_param(0, 700)
    car.save()
    assert car.read_params()[0] == 700  # the save frame came before this read
    car.close()
    appmode_board.restart()
    car = AppPort(appmode_board.port)
    assert car.read_params()[0] == 700
    car.close()


@pytest.mark.appmode_board(drive="mecanum")
def test_uart2_velocity_and_the_encoder_report(appmode_board):
    control = ControlPort(appmode_board.uart2)
    control.encoder_report(True)
    control.velocity(0, 300, 0)
    reports = control.reports(1.0)
    assert reports, "no encoder report in 1 s"
    last = reports[-1]
    assert [target for target, _ in last] == [300, 300, 300, 300]
    assert all(actual > 250 for _, actual in last)
    assert appmode_board.state.driver == "uart2"
    control.encoder_report(False)
    control.close()  # sends the zero velocity frame
    appmode_board.wait_until(lambda s: not s.moving, timeout=2, what="a standstill")
