"""The ROS messages the node sends and takes, as CDR (little-endian, with its 4-byte
encapsulation header, as rmw_zenoh carries it), through rosbags' type store of the
distro spoken: what each is for, and its RIHS01 type hash (REP-2016) as rosbags
computes it from the type's definition."""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore

from appmode.protocol.odometry import Pose2D
from appmode.protocol.sensed import YAW_WINDOW
from appmode.ros import interfaces

TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
ODOMETRY = "nav_msgs/msg/Odometry"
BATTERY = "sensor_msgs/msg/BatteryState"
IMU = "sensor_msgs/msg/Imu"
TF = "tf2_msgs/msg/TFMessage"
STRING = "std_msgs/msg/String"
FLOAT32 = "std_msgs/msg/Float32"
LOG = "rcl_interfaces/msg/Log"
PARAMETER_EVENT = "rcl_interfaces/msg/ParameterEvent"
TYPES = (TWIST, TWIST_STAMPED, ODOMETRY, BATTERY, IMU, TF, STRING, FLOAT32, LOG, PARAMETER_EVENT)
STORES = {"jazzy": Stores.ROS2_JAZZY, "humble": Stores.ROS2_HUMBLE}
UNKNOWN = -1.0
"""A covariance's first element when the quantity is not measured (REP 145)."""


class Messages:
    """The node's messages for one distro."""

    def __init__(self, distro: str) -> None:
        self.store = _store(distro)
        self.types = self.store.types

    def type_hash(self, ros_type: str) -> str:
        return str(self.store.hash_rihs01(ros_type))

    def service_hash(self, ros_type: str) -> str:
        return interfaces.service_hash(ros_type, self.store)

    def request(self, payload: bytes, ros_type: str) -> Any:
        """A service's request; ValueError if the payload is not one."""
        try:
            return self.store.deserialize_cdr(payload, f"{ros_type}_Request")
        except Exception as exc:  # bytes from anyone: whatever rosbags raises of them
            raise ValueError(f"not a {ros_type} request: {type(exc).__name__}") from None

    def cdr(self, message: Any, ros_type: str) -> bytes:
        return bytes(self.store.serialize_cdr(message, ros_type))

    def log(self, level: int, name: str, text: str, time_ns: int) -> bytes:
        """A line the node logs, as rcl_interfaces/Log (/rosout)."""
        stamp = self._stamp(time_ns)
        message = self._make(
            LOG, stamp=stamp, level=level, name=name, msg=text, file="", function="", line=0
        )
        return self.cdr(message, LOG)

    def _make(self, ros_type: str, **fields: Any) -> Any:
        return self.types[ros_type](**fields)

    def _stamp(self, time_ns: int) -> Any:
        return self._make(
            "builtin_interfaces/msg/Time", sec=time_ns // 10**9, nanosec=time_ns % 10**9
        )

    def _header(self, time_ns: int, frame: str) -> Any:
        return self._make("std_msgs/msg/Header", stamp=self._stamp(time_ns), frame_id=frame)

    def _vector(self, x: float, y: float, z: float) -> Any:
        return self._make("geometry_msgs/msg/Vector3", x=x, y=y, z=z)

    def _quaternion(self, roll: float, pitch: float, yaw: float) -> Any:
        cr, sr = math.cos(roll / 2), math.sin(roll / 2)
        cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
        cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
        return self._make(
            "geometry_msgs/msg/Quaternion",
            x=sr * cp * cy - cr * sp * sy,
            y=cr * sp * cy + sr * cp * sy,
            z=cr * cp * sy - sr * sp * cy,
            w=cr * cp * cy + sr * sp * sy,
        )

    def odometry(
        self, pose: Pose2D, time_ns: int, frame: str, child: str, variance: float
    ) -> bytes:
        """Dead reckoning: the pose's x, y and yaw with a variance of `variance` (m², rad²,
        growing with the distance driven), the twist's from the board's velocity."""
        position = self._make("geometry_msgs/msg/Point", x=pose.x, y=pose.y, z=0.0)
        orientation = self._quaternion(0.0, 0.0, pose.yaw)
        pose_covariance = _diagonal(6, (variance, variance, 1e6, 1e6, 1e6, variance))
        twist_covariance = _diagonal(6, (1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3))
        message = self._make(
            ODOMETRY,
            header=self._header(time_ns, frame),
            child_frame_id=child,
            pose=self._make(
                "geometry_msgs/msg/PoseWithCovariance",
                pose=self._make(
                    "geometry_msgs/msg/Pose", position=position, orientation=orientation
                ),
                covariance=pose_covariance,
            ),
            twist=self._make(
                "geometry_msgs/msg/TwistWithCovariance",
                twist=self._make(
                    TWIST,
                    linear=self._vector(pose.forward, pose.left, 0.0),
                    angular=self._vector(0.0, 0.0, pose.turn),
                ),
                covariance=twist_covariance,
            ),
        )
        return self.cdr(message, ODOMETRY)

    def transform(self, pose: Pose2D, time_ns: int, frame: str, child: str) -> bytes:
        """`frame` → `child` as a TFMessage of one transform."""
        stamped = self._make(
            "geometry_msgs/msg/TransformStamped",
            header=self._header(time_ns, frame),
            child_frame_id=child,
            transform=self._make(
                "geometry_msgs/msg/Transform",
                translation=self._vector(pose.x, pose.y, 0.0),
                rotation=self._quaternion(0.0, 0.0, pose.yaw),
            ),
        )
        return self.cdr(self._make(TF, transforms=[stamped]), TF)

    def battery(self, percent: float, time_ns: int, frame: str) -> bytes:
        """The battery as the board reports it: a percentage (REP: 0–1), and the voltage
        it is made from (§3.2: (cV − 1110) × 2 / 3: 12.60 V at 100 %, where the firmware
        caps it, and 11.10 V at 0 %, where the sheet's floors it: the voltage is then at
        least, or at most, that; the reference firmware's −740 % at power-up is 0 V);
        nothing else measured (NaN)."""
        fraction = max(0.0, min(1.0, percent / 100))
        return self._battery(volts_of(percent), fraction, time_ns, frame)

    def battery_volts(self, volts: float, time_ns: int, frame: str) -> bytes:
        """A battery's voltage as the board measured it (a chassis port's status, in mV);
        its percentage not known (NaN)."""
        return self._battery(volts, math.nan, time_ns, frame)

    def _battery(self, volts: float, fraction: float, time_ns: int, frame: str) -> bytes:
        kind = self.types[BATTERY]
        nan = math.nan
        message = self._make(
            BATTERY,
            header=self._header(time_ns, frame),
            voltage=volts,
            temperature=nan,
            current=nan,
            charge=nan,
            capacity=nan,
            design_capacity=nan,
            percentage=fraction,
            power_supply_status=kind.POWER_SUPPLY_STATUS_UNKNOWN,
            power_supply_health=kind.POWER_SUPPLY_HEALTH_UNKNOWN,
            power_supply_technology=kind.POWER_SUPPLY_TECHNOLOGY_UNKNOWN,
            present=True,
            cell_voltage=np.zeros(0, dtype=np.float32),
            cell_temperature=np.zeros(0, dtype=np.float32),
            location="",
            serial_number="",
        )
        return self.cdr(message, BATTERY)

    def imu_raw(
        self,
        angular_velocity: tuple[float, float, float],
        acceleration: tuple[float, float, float],
        time_ns: int,
        frame: str,
    ) -> bytes:
        """An IMU's rates and accelerations as it measured them (a chassis port's status):
        no orientation (covariance −1, REP 145)."""
        unknown = np.zeros(9)
        unknown[0] = UNKNOWN
        message = self._make(
            IMU,
            header=self._header(time_ns, frame),
            orientation=self._make("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=unknown,
            angular_velocity=self._vector(*angular_velocity),
            angular_velocity_covariance=_diagonal(3, (GYRO_VARIANCE,) * 3),
            linear_acceleration=self._vector(*acceleration),
            linear_acceleration_covariance=_diagonal(3, (ACCEL_VARIANCE,) * 3),
        )
        return self.cdr(message, IMU)

    def imu(
        self,
        roll: float,
        pitch: float,
        yaw: float,
        time_ns: int,
        frame: str,
        rates: tuple[float, ...] | None = None,
    ) -> bytes:
        """The board's attitude (radians, REP 103) as an orientation with whole degrees'
        variance; its `rates` (rad/s, from the attitude over YAW_WINDOW s) as the angular
        velocity, with a whole degree's over that window as variance (none: covariance
        −1); acceleration not given (covariance −1)."""
        degree = math.radians(1.0) ** 2
        unknown = np.zeros(9)
        unknown[0] = UNKNOWN
        rate = degree / YAW_WINDOW**2
        message = self._make(
            IMU,
            header=self._header(time_ns, frame),
            orientation=self._quaternion(roll, pitch, yaw),
            orientation_covariance=_diagonal(3, (degree, degree, degree)),
            angular_velocity=self._vector(*(rates or (0.0, 0.0, 0.0))),
            angular_velocity_covariance=(
                unknown.copy() if rates is None else _diagonal(3, (rate, rate, rate))
            ),
            linear_acceleration=self._vector(0.0, 0.0, 0.0),
            linear_acceleration_covariance=unknown.copy(),
        )
        return self.cdr(message, IMU)

    def text(self, data: str) -> bytes:
        return self.cdr(self._make(STRING, data=data), STRING)

    def float32(self, value: float) -> bytes:
        """A std_msgs/Float32 (the vendor driver's PowerVoltage, in volts)."""
        return self.cdr(self._make(FLOAT32, data=value), FLOAT32)

    def twist(self, payload: bytes, stamped: bool) -> tuple[float, float, float, float]:
        """A Twist's (or TwistStamped's) linear x and y and angular z, and its angular x
        and y summed (a car ignores them); ValueError if it is not one."""
        ros_type = TWIST_STAMPED if stamped else TWIST
        try:
            message = self.store.deserialize_cdr(payload, ros_type)
        except Exception as exc:  # bytes from anyone: whatever rosbags raises of them
            raise ValueError(f"not a {ros_type}: {type(exc).__name__}") from None
        twist = message.twist if stamped else message
        values = (twist.linear.x, twist.linear.y, twist.angular.z)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"a Twist of {values}: not finite")
        return (*values, abs(twist.angular.x) + abs(twist.angular.y))


@cache
def _store(distro: str) -> Any:
    """The distro's type store, with the services' requests and responses."""
    store = get_typestore(STORES[distro])
    interfaces.register(store)
    return store


GYRO_VARIANCE = 1e-4
"""(rad/s)²: a MEMS gyro's noise, about 0.01 rad/s."""
ACCEL_VARIANCE = 2.5e-3
"""(m/s²)²: its accelerometer's, about 0.05 m/s²."""


def volts_of(percent: float) -> float:
    """The voltage an APP record's battery percentage is made from (§3.2)."""
    return (min(100.0, percent) * 1.5 + 1110) / 100


def _diagonal(size: int, values: tuple[float, ...]) -> Any:
    matrix = np.zeros(size * size)
    for i, value in enumerate(values):
        matrix[i * size + i] = value
    return matrix
