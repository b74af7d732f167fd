"""What `pip install .` puts on a machine: the wheel ships the conformance suite (kept in
the repository's transcripts/suite, mapped into the package at build time), the protocol
reference (docs/protocol.md, likewise) and the pytest plugin's entry point, and an
installed `appmode conform` runs that suite and `appmode protocol` reads that reference."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from tests.support.processes import ROOT


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(ROOT)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    (found,) = out.glob("appmode-*.whl")
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


def test_the_default_wheel_is_pure_python(wheel: Path) -> None:
    """The compiled build is made only when asked for (HATCH_BUILD_HOOKS_ENABLE=1):
    `pip install .` needs no C compiler, on any system."""
    assert wheel.name.endswith("-py3-none-any.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert not [n for n in names if n.endswith((".so", ".pyd"))]


def test_compiled_modules_beside_the_sources_are_as_new_as_them() -> None:
    """The compiled build leaves its modules beside their sources, where Python imports
    them first: one older than its source (edited since) would be run in its place."""
    stale = [
        compiled.relative_to(ROOT).as_posix()
        for pattern in ("*.so", "*.pyd")
        for compiled in (ROOT / "appmode").rglob(pattern)
        if compiled.stat().st_mtime < source_of(compiled).stat().st_mtime
    ]
    assert not stale, (
        f"{', '.join(stale)}: older than their sources; build again "
        "(HATCH_BUILD_HOOKS_ENABLE=1 pip install .) or remove them (rm appmode/*/*.so *__mypyc*.so)"
    )


def source_of(compiled: Path) -> Path:
    """The source a compiled module was built from: firmware.cpython-311-….so, firmware.py."""
    return compiled.with_name(compiled.name.split(".")[0] + ".py")
