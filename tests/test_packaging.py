"""What `pip install .` puts on a machine: the wheel ships the conformance suite (kept in
the repository's transcripts/suite, mapped into the package at build time), the protocol
reference (docs/protocol.md, likewise) and the pytest plugin's entry point, and an
installed `appmode conform` runs that suite and `appmode protocol` reads that reference."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import pytest

from tests.support.processes import ROOT

if sys.version_info >= (3, 11):
    pass
else:  # pragma: no cover - Python 3.10
    pass

START = time.time()
"""When this module was loaded: a build after it leaves nothing in the checkout."""


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(ROOT)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    (found,) = out.glob("appmode_car-*.whl")
    return found


def test_the_wheel_ships_the_suite_from_transcripts(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    suite = sorted(
        p.relative_to(ROOT / "transcripts").as_posix()
        for p in (ROOT / "transcripts" / "suite").rglob("*.transcript")
    )
    assert len(suite) > 40
    assert {f"appmode/{name}" for name in suite} <= names
    assert not [n for n in names if n.startswith(("transcripts/", "tests/", "examples/"))]
    entry_points = next(n for n in names if n.endswith(".dist-info/entry_points.txt"))
    text = zipfile.ZipFile(wheel).read(entry_points).decode()
    assert "[pytest11]\nappmode = appmode.testing.plugin" in text


def installed(site: Path, tmp_path: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """`appmode ARGS` as installed in `site`, run from a folder away from the checkout."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir(exist_ok=True)
    return subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from appmode.cli.main import main; sys.exit(main())",
            *args,
        ],
        cwd=elsewhere,
        env={"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


def test_an_installed_appmode_conform_runs_the_shipped_suite(wheel: Path, tmp_path: Path) -> None:
    site = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site), wheel],
        check=True,
        capture_output=True,
        timeout=300,
    )
    done = installed(site, tmp_path, "conform")
    assert done.returncode == 0, done.stderr
    assert f"the shipped suite: {site / 'appmode' / 'suite'}" in done.stdout
    sheet = len(list((ROOT / "transcripts" / "suite").glob("*.transcript")))
    sheet += len(list((ROOT / "transcripts" / "suite" / "uart2").glob("*.transcript")))
    assert f"{sheet} passed, 0 failed" in done.stdout
    reference = installed(site, tmp_path, "protocol", "8.3")
    assert reference.returncode == 0, reference.stderr
    assert reference.stdout.startswith("### 8.3 Who drives")  # from the installed copy
    assert (site / "appmode" / "docs" / "protocol.md").read_bytes() == (
        ROOT / "docs" / "protocol.md"
    ).read_bytes()


def test_the_default_wheel_is_pure_python_and_named_appmode_car(wheel: Path) -> None:
    """Issue 79: `pip install .` (and each extra added later) compiles nothing, so that it
    takes seconds; the compiled build is APPMODE_COMPILE=1's (CI builds and tests it:
    `python -m bench.compiled`). The distribution is appmode-car (PyPI's `appmode` is a
    Jupyter extension); the import name and the command stay appmode."""
    assert wheel.name.startswith("appmode_car-") and wheel.name.endswith("-py3-none-any.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert not [n for n in names if n.endswith((".so", ".pyd"))]
    metadata = next(n for n in names if n.endswith(".dist-info/METADATA"))
    assert "\nName: appmode-car\n" in zipfile.ZipFile(wheel).read(metadata).decode()
    assert "appmode/__init__.py" in names
    assert not [p for p in (ROOT / "appmode").rglob("*.so") if p.stat().st_mtime > START]


def test_compiled_modules_beside_the_sources_are_as_new_as_them() -> None:
    """Compiled modules beside their sources (`python -m bench.compiled` puts them there,
    for CI's compiled tests and the benchmarks) are what Python imports first: one older
    than its source (edited since) would be run in its place."""
    stale = [
        compiled.relative_to(ROOT).as_posix()
        for pattern in ("*.so", "*.pyd")
        for compiled in (ROOT / "appmode").rglob(pattern)
        if compiled.stat().st_mtime < source_of(compiled).stat().st_mtime
    ]
    assert not stale, (
        f"{', '.join(stale)}: older than their sources; put new ones there "
        "(python -m bench.compiled) or remove them (python -m bench.compiled --remove)"
    )


def source_of(compiled: Path) -> Path:
    """The source a compiled module was built from: firmware.cpython-311-….so, firmware.py."""
    return compiled.with_name(compiled.name.split(".")[0] + ".py")


def test_an_installed_appmode_writes_nothing_into_its_folder(wheel: Path, tmp_path: Path) -> None:
    """Installed, the program drives, decodes and shows profiles, and its folder gains no
    file (Python's own bytecode apart); installed read-only (for root, whom no file mode
    stops, a read-only mount of it), it does the same."""
    site = Path(tempfile.mkdtemp(prefix="appmode-ro-"))  # under /tmp: nobody can reach it
    home = Path(tempfile.mkdtemp(prefix="appmode-home-"))
    try:
        subprocess.run(
            [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", site, wheel],
            check=True,
            capture_output=True,
            timeout=300,
        )
        home.chmod(0o777)
        before = sorted(site.rglob("*"))
        _run_installed(site, home, {"PYTHONDONTWRITEBYTECODE": "1"})
        assert sorted(site.rglob("*")) == before, "written into the installed package"
        for path in (site, *site.rglob("*")):
            path.chmod(0o555 if path.is_dir() else 0o444)
        _run_installed(site, home, {}, read_only=os.geteuid() == 0)
        assert sorted(site.rglob("*")) == before
    finally:
        for path in (site, *site.rglob("*")):
            if path.is_dir():
                path.chmod(0o755)
        shutil.rmtree(site, ignore_errors=True)
        shutil.rmtree(home, ignore_errors=True)


def _run_installed(site: Path, home: Path, env: dict[str, str], read_only: bool = False) -> None:
    """Commands of the program installed in `site`, and a program that imports appmode
    and opens `sim://` with pyserial, each of which must succeed (`read_only`: with
    `site` mounted read-only, in a mount namespace of their own: util-linux's unshare)."""
    program = "import sys; from appmode.cli.entry import main; sys.exit(main())"
    opens = "import appmode, serial; print(serial.serial_for_url('sim://'))"
    runs = [
        [program, "decode"],
        [program, "profile", "show", "minibalance", "--toml"],
        [program, "send", "sim://?profile=minibalance", "J", "A", "wait:0.3"],
        [program, "params", "sim://", "--set", "max_speed=800"],
        [opens],
    ]
    for args in runs:
        command = [sys.executable, "-c", *args]
        if read_only:
            mount = f"mount --bind {site} {site} && mount -o remount,ro,bind {site}"
            command = ["unshare", "--mount", "sh", "-c", f'{mount} && exec "$@"', "-", *command]
        done = subprocess.run(
            command,
            cwd=home,
            env={"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin", "HOME": str(home), **env},
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        assert done.returncode == 0, (args[1:], done.stderr)
