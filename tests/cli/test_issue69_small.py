"""Issue 69.10, the small ones a user meets: `-V`, what `--help` promises of the version,
`plot FILE` with no `-o`, and the documentation site read from files."""

from __future__ import annotations

import shutil
from pathlib import Path

from tests.support.processes import ROOT, run


def test_dash_v_prints_the_version_and_help_promises_the_commit_only_in_a_checkout() -> None:
    short, long = run("-V"), run("--version")
    assert short.returncode == 0 and short.stdout == long.stdout
    assert short.stdout.startswith("appmode ")
    assert "(and, run from a git checkout, its commit)" in run("--help").stdout


def test_plot_without_o_writes_beside_the_file_and_never_over_one(tmp_path: Path) -> None:
    source = tmp_path / "drive.transcript"
    shutil.copy(ROOT / "transcripts" / "suite" / "s4_letters_omni.transcript", source)
    done = run("plot", str(source))
    assert done.returncode == 0, done.stderr
    image = tmp_path / "drive.png"
    assert image.read_bytes().startswith(b"\x89PNG")
    assert f"wrote {image}" in done.stderr
    image.write_bytes(b"mine")
    again = run("plot", str(source))
    assert again.returncode == 2 and image.read_bytes() == b"mine", "not replaced"
    assert f"{image} is already there: name the image with -o PNG" in again.stderr


def test_the_site_links_pages_as_files() -> None:
    """Opened from file://, a link to a folder lands on a directory listing."""
    config = (ROOT / "mkdocs.yml").read_text()
    assert "use_directory_urls: false" in config
