"""Put the compiled build's modules beside their sources in a checkout, where Python
imports them first: the wheel `APPMODE_COMPILE=1 pip install .` builds (hatch_build.py) is
made, each module the configuration lists is checked to be in it, and they are copied out
of it. The checkout's tests and benchmarks then run
what an installed appmode runs (CI's compiled tests; docs/benchmarks.md's tables).
Edit a compiled module's source and this is to be run again (tests/test_packaging.py
fails while one is older than its source); `--remove` takes them away."""

from __future__ import annotations

import argparse
import os
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


def listed() -> list[str]:
    """The modules pyproject.toml has compiled."""
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    return list(config["tool"]["hatch"]["build"]["targets"]["wheel"]["hooks"]["custom"]["compile"])


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
            env={**os.environ, "APPMODE_COMPILE": "1"},
        )
        (wheel,) = Path(out).glob("appmode_car-*.whl")
        with zipfile.ZipFile(wheel) as built:
            names = [n for n in built.namelist() if n.endswith(SUFFIXES)]
            built.extractall(ROOT, names)
    if not names:
        raise SystemExit("the build was pure Python: this machine cannot compile appmode")
    modules = sorted(n.split(".")[0] + ".py" for n in names if "__mypyc" not in n)
    if modules != sorted(listed()):
        raise SystemExit(f"compiled {modules}, not the configuration's {sorted(listed())}")
    print(f"{len(names)} compiled modules put beside their sources in {ROOT}")


if __name__ == "__main__":
    main()
