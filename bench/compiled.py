"""Put the compiled build's modules beside their sources in a checkout, where Python
imports them first: the wheel `pip install .` builds (hatch_build.py) is made, and its
compiled modules are copied out of it. The checkout's tests and benchmarks then run
what an installed appmode runs (CI's compiled tests; docs/benchmarks.md's tables).
Edit a compiled module's source and this is to be run again (tests/test_packaging.py
fails while one is older than its source); `--remove` takes them away."""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SUFFIXES = (".so", ".pyd")


def compiled_in(root: Path) -> list[Path]:
    """The compiled modules beside the sources in checkout `root`, mypyc's runtime too."""
    return [p for p in (*root.glob("*"), *(root / "appmode").rglob("*")) if p.suffix in SUFFIXES]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--remove", action="store_true", help="remove them instead")
    args = parser.parse_args()
    for old in compiled_in(ROOT):
        old.unlink()
    if args.remove:
        return
    with tempfile.TemporaryDirectory() as out:
        subprocess.run(
            [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", out, str(ROOT)],
            check=True,
        )
        (wheel,) = Path(out).glob("appmode-*.whl")
        with zipfile.ZipFile(wheel) as built:
            names = [n for n in built.namelist() if n.endswith(SUFFIXES)]
            built.extractall(ROOT, names)
    if not names:
        raise SystemExit("the build was pure Python: this machine cannot compile appmode")
    print(f"{len(names)} compiled modules put beside their sources in {ROOT}")


if __name__ == "__main__":
    main()
