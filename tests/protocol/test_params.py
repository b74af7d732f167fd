"""docs/protocol.md §5 (parameters) and §6 (system-mode bits)."""

from __future__ import annotations

import pytest

from appmode.protocol import param_values, params


def test_s5_nine_parameters_in_index_order_with_ranges_and_defaults() -> None:
    table = [(p.index, p.name, p.maximum, p.default) for p in params.PARAMS]
    assert table == [
        (0, "max_speed", 65535, 500),
        (1, "max_position", 65535, 10000),
        (2, "position_kp", 4294967295, 20),
        (3, "position_ki", 4294967295, 0),
        (4, "position_kd", 4294967295, 10),
        (5, "velocity_kp", 4294967295, 10),
        (6, "velocity_ki", 4294967295, 10),
        (7, "gyro_compensation", 4294967295, 0),
        (8, "system_mode", 65535, 0),
    ]
    assert all(p.minimum == 0 for p in params.PARAMS)


@pytest.mark.parametrize("param", params.PARAMS, ids=lambda p: p.name)
def test_s5_range_bounds(param: params.Param) -> None:
    assert params.value_error(param.index, param.maximum + 1) is not None
    assert params.value_error(param.index, -1) is not None
    assert params.value_error(param.index, 0) is None
    if param.index != params.SYSTEM_MODE:
        assert params.value_error(param.index, param.maximum) is None


def test_s5_range_error_names_parameter_and_range() -> None:
    with pytest.raises(ValueError, match=r"max_speed \(parameter 0\) must be in 0–65535"):
        params.check_value(0, 70000)


def test_s6_drive_types_4_to_7_are_invalid() -> None:
    for value in range(8):
        error = params.value_error(params.SYSTEM_MODE, 0x100 | value)
        assert (error is None) == (value < 4), value
    assert params.drive_type(3) is params.DriveType.DIFF_GYRO
    assert params.drive_type(5) is None


def test_s6_bits_6_and_7_are_never_saved() -> None:
    values = list(params.DEFAULTS)
    values[params.SYSTEM_MODE] = 0xFFC3  # every bit but 2-5
    assert params.saved_form(values)[params.SYSTEM_MODE] == 0xFF03
    assert params.UNSAVED_MASK == 0xC0


def test_s6_named_bits() -> None:
    assert params.MODE_BIT["gyro_calibration"] == 1 << 3
    assert params.MODE_BIT["heading_correction"] == 1 << 4
    assert params.MODE_BIT["motor_reverse"] == 1 << 8
    assert params.MODE_BIT["gyro_reverse"] == 1 << 11


def test_lookup_by_name_or_index() -> None:
    assert param_values.lookup(param_values.SHEET, "max_speed") == 0
    assert param_values.lookup(param_values.SHEET, "8") == params.SYSTEM_MODE
    with pytest.raises(ValueError, match="unknown parameter 'speed'"):
        param_values.lookup(param_values.SHEET, "speed")
