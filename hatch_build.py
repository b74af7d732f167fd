"""The wheel's build hook: with APPMODE_COMPILE=1 set, the served board's hot modules
compiled with mypyc where this machine can compile them (a C compiler and Python's
headers); pure Python otherwise, and by default, so that an install, and every extra
added later, takes seconds (docs/simulated-board.md, "The compiled build"). The modules
compile in a copy of the package, so the checkout is left as it was; a failed compile
warns and builds pure Python."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path
from typing import Any

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

COMPILE = "APPMODE_COMPILE"
"""Set to 1 in the environment, the build is compiled where the machine can."""


def compiler() -> str | None:
    """The C compiler Python's own build used, if this machine has it and Python's headers."""
    if sys.platform == "win32":  # MSVC is not found this way: pure Python
        return None
    command = (sysconfig.get_config_var("CC") or "cc").split()
    found = shutil.which(command[0]) if command else None
    headers = Path(sysconfig.get_paths()["include"], "Python.h")
    return found if found and headers.exists() else None


class CompiledBuild(BuildHookInterface):  # type: ignore[type-arg]
    """Compiles `compile` (the config's list of modules) into the wheel, if it can."""

    PLUGIN_NAME = "custom"
    _kept: Path | None = None
    """Where the compiled modules wait for the wheel (until `finalize`)."""

    def _wanted(self) -> bool:
        return os.environ.get(COMPILE, "") == "1" and compiler() is not None

    def dependencies(self) -> list[str]:
        return ["mypy>=1.8", "setuptools>=61"] if self._wanted() else []

    def initialize(self, version: str, build_data: dict[str, Any]) -> None:
        if self.target_name != "wheel" or version == "editable" or not self._wanted():
            return  # an editable install runs its sources as they are edited
        modules = list(self.config.get("compile", []))
        with tempfile.TemporaryDirectory(prefix="appmode-build-") as temp:
            copy = Path(temp)
            shutil.copytree(
                Path(self.root, "appmode"),
                copy / "appmode",
                ignore=shutil.ignore_patterns("__pycache__", "*.so", "*.pyd"),
            )
            done = subprocess.run(
                [sys.executable, "-m", "mypyc", "--ignore-missing-imports", *modules],
                cwd=copy,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                text=True,
                check=False,
            )
            built = [  # the modules, and mypyc's runtime beside the package
                p
                for p in (*copy.glob("*"), *copy.joinpath("appmode").rglob("*"))
                if p.suffix in (".so", ".pyd")
            ]
            if done.returncode != 0 or not built:
                last = (done.stdout.strip().splitlines() or ["no output"])[-1]
                self.app.display_warning(
                    f"appmode: the compiled build failed ({last}); building pure Python"
                )
                return
            kept = self._kept = Path(tempfile.mkdtemp(prefix="appmode-compiled-"))
            for module in built:
                target = kept / module.relative_to(copy)
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(module, target)
                build_data["force_include"][str(target)] = module.relative_to(copy).as_posix()
        build_data["pure_python"] = False
        build_data["infer_tag"] = True

    def finalize(self, version: str, build_data: dict[str, Any], artifact: str) -> None:
        """The compiled modules are in the wheel: their copies go."""
        kept = self._kept
        if kept is not None:
            shutil.rmtree(kept, ignore_errors=True)
