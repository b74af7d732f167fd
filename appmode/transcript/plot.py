"""`appmode plot`: a transcript's telemetry drawn to a PNG — velocities, attitude and
battery over time with the commands marked, a UART2 transcript's wheels, or a chassis
port's status in SI. The file is
read once as it streams, each series reduced to what the picture can show (envelope):
memory is bounded whatever the file's size."""

from __future__ import annotations

import re
import sys
import textwrap
from collections.abc import Iterator
from io import BytesIO
from pathlib import Path
from typing import Any

from appmode.board.profiles import profile_named
from appmode.errors import AppmodeError
from appmode.files import check_writable, write_whole
from appmode.protocol import app, chassis, control
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.reader import SENT2, SENT_CHASSIS
from appmode.protocol.transcript import Comment, Directive, Entry
from appmode.transcript.dump import decoded, needs_of
from appmode.transcript.envelope import Envelope, Marks
from appmode.transcript.reading import iter_lines

LABEL_GAP = 0.012
"""Fraction of the time axis two command labels need between them (8 pt text, 11 in)."""
VELOCITY_LABELS = ("x (lateral, right +)", "y (forward +)", "z (rotation, cw +)", "extra")


def command_labels(commands: list[tuple[float, str]], gap: float) -> list[tuple[float, str]]:
    """One label per group of commands closer than `gap` seconds: their texts joined,
    at the first one's time, so that labels never overlap."""
    groups: list[tuple[float, list[str]]] = []
    for t, text in commands:
        if groups and t - groups[-1][0] < gap:
            groups[-1][1].append(text)
        else:
            groups.append((t, [text]))
    labels = []
    for t, texts in groups:
        label = " ".join(texts)
        labels.append((t, label if len(label) <= 16 else label[:15] + "…"))
    return labels


class _Read:
    """The file's lines as it streams, its title (the first comment) noted on the way."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.title = ""

    def items(self) -> Iterator[Entry | Directive]:
        warn = lambda text: print(f"appmode: WARNING: {text}", file=sys.stderr)  # noqa: E731
        for item in iter_lines(self.path, warn):
            if isinstance(item, Comment):
                self.title = self.title or item.text
            else:
                yield item


class _Telemetry:
    """What an APP-port plot draws, reduced: each A and B field, the commands sent."""

    def __init__(self, layout: Layout) -> None:
        self.a = [Envelope() for _ in layout.a_fields]
        self.b = [Envelope() for _ in layout.b_fields]
        self.commands = Marks()


class _Wheels:
    """What a UART2 plot draws, reduced: each wheel's actual and target speed, and the
    frames sent."""

    def __init__(self) -> None:
        self.actual: list[Envelope] = []
        self.target: list[Envelope] = []
        self.frames = Marks()

    def add(self, t: float, report: control.EncoderReport) -> None:
        while len(self.actual) < len(report.actuals):
            self.actual.append(Envelope())
            self.target.append(Envelope())
        for i, (actual, target) in enumerate(zip(report.actuals, report.targets, strict=False)):
            self.actual[i].add(t, actual)
            self.target[i].add(t, target)


class _Status:
    """What a chassis plot draws, reduced: the velocity, the IMU and the battery of each
    status frame (SI), and the velocities sent."""

    NAMES = ("forward m/s", "left m/s", "turn rad/s", "accel x m/s²", "accel y m/s²",
             "gyro z rad/s", "battery V")  # fmt: skip

    def __init__(self) -> None:
        self.series = [Envelope() for _ in self.NAMES]
        self.frames = Marks()

    def add(self, t: float, status: chassis.Status) -> None:
        twist = status.twist
        ax, ay, _ = status.acceleration
        values = (twist.forward, twist.left, twist.turn, ax, ay, status.angular_velocity[2])
        for envelope, value in zip(self.series, (*values, status.volts), strict=True):
            envelope.add(t, value)


def run_plot(path: str, output: str, profile: str | None = None, chassis_only: bool = False) -> int:
    """Velocities, attitude and battery over time, with the commands marked; the fields
    named as `profile` lays them out (default: the transcript's `@board profile=…`);
    `chassis_only`: the chassis port's status, whatever else the transcript holds."""
    check_writable(output, "plot")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise AppmodeError(
            "appmode plot needs matplotlib: pip install matplotlib (or, in a checkout of "
            "appmode, pip install '.[plot]')"
        ) from None
    given = profile_named(profile) if profile else None  # a file the @board line may name
    needs = needs_of(path, lambda text: None)  # the second pass warns
    layout = (given or needs.profile).a_layout
    read, seen, wheels, status = _Read(path), _Telemetry(layout), _Wheels(), _Status()
    for t, direction, event in decoded(read.items(), needs.drive, path, layout):
        if isinstance(event, chassis.Status):
            status.add(t, event)
        elif isinstance(event, chassis.Command) and direction == SENT_CHASSIS:
            status.frames.add(t, f"{event.vx / 1000:g},{event.vy / 1000:g},{event.wz / 1000:g}")
        elif isinstance(event, (app.Velocity, app.Attitude, app.OtherRecord)):
            letter, values = event.letter, event.values
            fields = seen.a if letter == "A" else seen.b if letter == "B" else []
            if len(values) == len(fields):
                for envelope, value in zip(fields, values, strict=True):
                    envelope.add(t, value)
        elif isinstance(event, control.EncoderReport):
            wheels.add(t, event)
        elif direction == ">" and isinstance(event, app.Command):
            seen.commands.add(t, event.raw.decode("latin-1"))
        elif direction == SENT2 and not isinstance(event, control.ERRORS):
            kind = type(event).__name__.removesuffix("Frame")
            wheels.frames.add(t, re.sub(r"(?<!^)(?=[A-Z])", " ", kind).lower())
    title = _title(path, read.title)
    if chassis_only and not status.series[0].count:
        raise AppmodeError(f"{path} has no chassis status frames (§15) to plot")
    if chassis_only:
        return _plot_status(plt, status, title, output)
    if any(envelope.count for envelope in seen.a + seen.b):
        return _plot_app(plt, seen, layout, title, output)
    if wheels.actual:
        return _plot_wheels(plt, wheels, title, output)
    if status.series[0].count:
        return _plot_status(plt, status, title, output)
    raise AppmodeError(
        f"{path} has no A or B records, no encoder reports (UART2, §12) and no chassis "
        "status frames (§15) to plot"
    )


def _plot_app(plt: Any, seen: _Telemetry, layout: Layout, title: str, output: str) -> int:
    from matplotlib.ticker import MaxNLocator

    fig, (strip, vel, att, bat) = plt.subplots(
        4, 1, sharex=True, figsize=(11, 8.5), height_ratios=(0.7, 3, 3, 2), layout="constrained"
    )
    names = VELOCITY_LABELS if layout is VELOCITY else layout.labels
    for i in layout.motion:
        vel.plot(*seen.a[i].points(), label=names[i], drawstyle="steps-post")
    unit = layout.a_fields[layout.motion[0]].unit if layout.motion else ""
    scaled = f"{layout.scale:g}·" if layout.scale != 1 else ""
    wraps = layout.a_fields[layout.motion[0]].wrap if layout.motion else None
    vel.set_ylabel(
        f"{unit or 'value'}"
        if layout.signed
        else f"|{scaled}v| ({unit})" + (f", wraps at {wraps}" if wraps else "")
    )
    shown = [(i, f) for i, f in enumerate(layout.b_fields) if not f.battery]
    for i, field in shown:
        att.plot(*seen.b[i].points(), label=field.label, drawstyle="steps-post")
    words = {"°": "degrees", "": "value"}
    att.set_ylabel(" / ".join(dict.fromkeys(words.get(f.unit, f.unit) for _, f in shown)))
    times, battery = _battery(layout, seen)
    bat.plot(times, battery, color="tab:green", drawstyle="steps-post")
    bat.set_ylabel("battery %")
    if battery:  # the range it spans, so that a change shows
        low, high = min(battery), max(battery)
        pad = max(2.0, (high - low) * 0.1)
        bat.set_ylim(low - pad, high + pad)
        bat.yaxis.set_major_locator(MaxNLocator(integer=True))
    bat.set_xlabel("time (s)")
    every = [t for e in seen.a + seen.b for t in e.points()[0]]
    _mark_commands(strip, (vel, att, bat), seen.commands.kept(), every)
    vel.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    att.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.suptitle(title, fontsize=11)
    return _save(plt, fig, output)


def _battery(layout: Layout, seen: _Telemetry) -> tuple[list[float], list[float]]:
    """The battery over time, from the B record's battery field, else the A record's."""
    held = next((i for i, f in enumerate(layout.b_fields) if f.battery), None)
    if held is not None:
        return seen.b[held].points()
    if layout.battery is not None:
        return seen.a[layout.battery].points()
    return [], []


def _plot_wheels(plt: Any, wheels: _Wheels, title: str, output: str) -> int:
    """A UART2 transcript: each wheel's target (dashed) and actual speed from the encoder
    reports (§12), the frames sent marked."""
    fig, (strip, axes) = plt.subplots(
        2, 1, sharex=True, figsize=(11, 6), height_ratios=(0.8, 4), layout="constrained"
    )
    for i, (actual, target) in enumerate(zip(wheels.actual, wheels.target, strict=True)):
        line = axes.plot(*actual.points(), label=f"wheel {'ABCD'[i]}")
        axes.plot(*target.points(), linestyle="--", color=line[0].get_color())
    axes.set_ylabel("wheel speed (dashed: target)")
    axes.set_xlabel("time (s)")
    axes.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    every = [t for e in wheels.actual for t in e.points()[0]]
    _mark_commands(strip, (axes,), wheels.frames.kept(), every)
    fig.suptitle(title, fontsize=11)
    return _save(plt, fig, output)


def _plot_status(plt: Any, status: _Status, title: str, output: str) -> int:
    """A chassis port's transcript: its status in SI, the velocities sent marked."""
    fig, (strip, vel, imu, bat) = plt.subplots(
        4, 1, sharex=True, figsize=(11, 8.5), height_ratios=(0.7, 3, 3, 2), layout="constrained"
    )
    for axes, shown in ((vel, range(3)), (imu, range(3, 6)), (bat, range(6, 7))):
        for i in shown:
            axes.plot(*status.series[i].points(), label=_Status.NAMES[i], drawstyle="steps-post")
        axes.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    vel.set_ylabel("velocity (SI)")
    imu.set_ylabel("IMU (SI)")
    bat.set_ylabel("battery V")
    bat.ticklabel_format(axis="y", useOffset=False)
    bat.set_xlabel("time (s)")
    every = [t for e in status.series for t in e.points()[0]]
    _mark_commands(strip, (vel, imu, bat), status.frames.kept(), every)
    fig.suptitle(title, fontsize=11)
    return _save(plt, fig, output)


def _mark_commands(
    strip: Any, axes: tuple[Any, ...], commands: list[tuple[float, str]], times: list[float]
) -> None:
    """The commands sent: a dotted line on each plot, their labels in a strip of their
    own above (never over the data)."""
    every = times + [t for t, _ in commands]
    span = max(every) - min(every) if every else 0.0
    strip.axis("off")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        for t, _ in commands:
            ax.axvline(t, color="grey", linestyle=":", linewidth=0.8)
    for t, text in command_labels(commands, span * LABEL_GAP):
        strip.annotate(
            text,
            (t, 0.0),
            xycoords=("data", "axes fraction"),
            fontsize=8,
            rotation=90,
            va="bottom",
            ha="center",
            color="dimgrey",
        )


def _title(path: str, title: str) -> str:
    """The file's name and the transcript's title, whole words in lines that fit."""
    return textwrap.fill(f"{Path(path).name} — {(title or 'telemetry').rstrip(',;: ')}", 110)


def _save(plt: Any, fig: Any, output: str) -> int:
    """Write the figure as a PNG, whole or not at all."""
    image = BytesIO()
    try:
        fig.savefig(image, format="png", dpi=110)
    finally:
        plt.close(fig)
    write_whole(output, image.getvalue(), "plot")
    return 0
