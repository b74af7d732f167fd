"""The architecture as the code has it (issues 25, 65): layers whose imports point only
down, folders within a layer for its sides (the APP port and the control port, the
host's Bluetooth links and the stand-in), small modules and functions, and no two
modules of one name but in sibling folders (`host/app/client.py`, `host/control/client.py`)."""

from __future__ import annotations

import ast
from pathlib import Path

from tests.support.source import parsed

PACKAGE = Path(__file__).resolve().parent.parent / "appmode"
LAYERS = (
    "protocol",
    "board",
    "line",
    "ports",
    "bluetooth",
    "host",
    "net",
    "transcript",
    "session",
    "viewers",
    "ros",
    "console",
    "web",
    "testing",
    "cli",
)
"""Bottom up: a subpackage imports only from its own layer or those below it."""
LEAVES = ("errors", "text", "files", "writer", "patterns", "throttle")
"""Modules of no layer, which any layer may use (they import only each other)."""
MAX_MODULE = 450
MAX_FUNCTION = 80


def modules() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def layer_of(name: str) -> int | None:
    """The layer of `appmode.x.y` (None for a leaf or the package itself)."""
    parts = name.split(".")
    if len(parts) < 2 or parts[1] in LEAVES or parts[1] in ("__init__", "__main__"):
        return None
    return LAYERS.index(parts[1])


def imported(path: Path) -> list[tuple[int, str]]:
    """(line, module) for every appmode module `path` imports, at run time or for types."""
    found = []
    for node in ast.walk(parsed(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("appmode"):
            found.append((node.lineno, node.module))
        elif isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names if a.name.startswith("appmode")]
    return found


def name_of(path: Path) -> str:
    return ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)


def test_every_subpackage_is_a_layer() -> None:
    packages = {p.relative_to(PACKAGE).parts[0] for p in modules() if p.parent != PACKAGE}
    assert packages == set(LAYERS)


def test_every_folder_is_a_package_that_says_what_it_holds() -> None:
    for folder in {p.parent for p in modules()}:
        init = folder / "__init__.py"
        assert init.exists(), f"{folder} has no __init__.py"
        assert ast.get_docstring(parsed(init.read_text(encoding="utf-8"))), f"{init}: say"


def test_imports_point_down_the_layers() -> None:
    upward = []
    for path in modules():
        here = layer_of(name_of(path))
        leaf = path.parent == PACKAGE and path.stem in LEAVES
        for line, module in imported(path):
            there = layer_of(module)
            if leaf and there is not None:
                upward.append(f"{name_of(path)}:{line} imports {module}: a leaf uses no layer")
            elif here is not None and there is not None and there > here:
                upward.append(f"{name_of(path)}:{line} imports {module}")
    assert not upward, "\n".join(upward)


def test_modules_and_functions_are_small() -> None:
    long = []
    for path in modules():
        text = path.read_text(encoding="utf-8")
        if len(text.splitlines()) > MAX_MODULE:
            long.append(f"{name_of(path)}: {len(text.splitlines())} lines")
        for node in ast.walk(parsed(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                size = (node.end_lineno or node.lineno) - node.lineno + 1
                if size > MAX_FUNCTION:
                    long.append(f"{name_of(path)}.{node.name}: {size} lines")
    assert not long, "\n".join(long)


def test_outside_cli_two_modules_share_a_name_only_in_sibling_folders() -> None:
    """The two ports' modules match by name (`app/state.py`, `control/state.py`): a
    reader finds one port's part by the other's; any other repeated name is a clash."""
    places: dict[str, list[Path]] = {}
    for path in modules():
        if path.parent.name != "cli" and path.stem != "__init__":
            places.setdefault(path.stem, []).append(path.parent)
    clashes = [
        f"{name}: {', '.join(str(f.relative_to(PACKAGE)) for f in folders)}"
        for name, folders in places.items()
        if len(folders) > 1 and len({f.parent for f in folders}) > 1
    ]
    assert clashes == [], "\n".join(clashes)


FILE_CALLS = {"open", "read_text", "read_bytes", "write_text", "write_bytes", "mkdir", "makedirs"}
"""Calls that open, read or write a file, or make a folder."""
FILE_MODULES = {"os", "pathlib", "io", "marshal", "shutil", "tempfile", "importlib.resources"}


def test_protocol_opens_no_file() -> None:
    """protocol/ is the grammars, with no I/O: it parses what it is given and writes to
    streams it is handed; the shipped profiles are its data (`protocol.profiles`)."""
    found = []
    for path in (PACKAGE / "protocol").rglob("*.py"):
        for node in ast.walk(parsed(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call):
                func = node.func
                name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
                if name in FILE_CALLS:
                    found.append(f"{name_of(path)}:{node.lineno}: {name}()")
            elif isinstance(node, ast.Import):
                found += [
                    f"{name_of(path)}:{node.lineno}: import {a.name}"
                    for a in node.names
                    if a.name in FILE_MODULES
                ]
            elif isinstance(node, ast.ImportFrom) and node.module in FILE_MODULES:
                found.append(f"{name_of(path)}:{node.lineno}: from {node.module} import …")
    assert not found, "\n".join(found)


def test_the_package_imports_nothing_of_the_command_line() -> None:
    """`import appmode` (a program's, the pytest plugin's) loads no part of cli/."""
    imports = [module for _, module in imported(PACKAGE / "__init__.py")]
    assert not [module for module in imports if module.startswith("appmode.cli")], imports


def test_the_command_line_uses_no_argparse_internals() -> None:
    """No private name of argparse's classes is read, set or overridden (the lazy list of
    commands is the COMMANDS table; the width goes in by formatter_class)."""
    import argparse

    private = {
        name
        for cls in vars(argparse).values()
        if isinstance(cls, type)
        for name in vars(cls)
        if name.startswith("_") and not name.startswith("__")
    }
    found = []
    for path in modules():
        tree = parsed(path.read_text(encoding="utf-8"))
        methods = [n for c in ast.walk(tree) if isinstance(c, ast.ClassDef) for n in c.body]
        for node in [*ast.walk(tree), *methods]:
            if isinstance(node, ast.Attribute) and node.attr in private:
                found.append(f"{name_of(path)}:{node.lineno}: .{node.attr}")
            elif node in methods and getattr(node, "name", "") in private:
                found.append(f"{name_of(path)}:{node.lineno}: def {getattr(node, 'name', '')}")
    assert not found, "\n".join(found)


PORT_CLASSES = {"Host", "ControlHost", "AppSession", "ControlSession", "HostState", "ControlState"}
"""The classes of one port's side: an isinstance on one asks which port a thing has."""
PORT_NAMES = {"app", "uart2"}
CHOOSE_PORTS = ("ports/", "session/", "host/app/", "host/control/", "net/remote_port.py")
"""Where a board's port is chosen and each port's side is opened (`ports.choice`,
`session.opener`), each port's own side (its host checks that it is given its port), and
a URL scheme's port class (`zenoh://` opens one side of a shared car): the only places
that may ask which port is driven."""


def port_questions(path: Path) -> list[str]:
    """Where `path` asks which port a host or session has: an isinstance on one port's
    class, a board choice's `control`, a comparison with a port's name or with a choice's
    `port` (a probe's `finding.kind`, what a port was heard to be, is no such question)."""
    found = []
    for node in ast.walk(parsed(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "isinstance":
            classes = node.args[1]
            names = classes.elts if isinstance(classes, ast.Tuple) else [classes]
            asked = {getattr(n, "id", getattr(n, "attr", "")) for n in names} & PORT_CLASSES
            found += [f"isinstance(…, {name})" for name in sorted(asked)]
        elif isinstance(node, ast.Attribute) and node.attr == "control":
            owner = getattr(node.value, "id", getattr(node.value, "attr", ""))
            if owner.endswith("choice"):
                found.append(f"{owner}.control")
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            kinds = [s for s in sides if isinstance(s, ast.Attribute) and s.attr == "kind"]
            named = [s for s in sides if isinstance(s, ast.Constant) and s.value in PORT_NAMES]
            ports = [
                s
                for s in sides
                if isinstance(s, ast.Attribute)
                and s.attr == "port"
                and getattr(s.value, "id", getattr(s.value, "attr", "")).endswith("choice")
            ]
            if (named and not kinds) or ports:
                found.append(f"a comparison with {ast.unparse(node)}")
    return [f"{name_of(path)}:{question}" for question in found]


def test_nothing_outside_ports_and_session_asks_which_port_is_driven() -> None:
    """The board is chosen once (`ports.choice`); sessions (`session.opener.SESSIONS`),
    a share's hosts (`host.kinds.HOSTS`) and the commands that differ by port (a table
    each, keyed by `BoardChoice.port`) are looked up, never branched on."""
    found = []
    for path in modules():
        if not path.relative_to(PACKAGE).as_posix().startswith(CHOOSE_PORTS):
            found += port_questions(path)
    assert not found, "\n".join(found)


def test_the_recording_formats_are_one_table_each_way() -> None:
    """A file's name chooses how it is written and its first bytes how it is read in one
    place (`protocol.formats.WRITERS`, `READERS`): no other module names a format's
    suffix or magic."""
    from appmode.protocol import formats

    named = {*formats.WRITERS, *(m.decode("latin-1") for m in formats.READERS)}
    found = []
    for path in modules():
        if path.name in ("formats.py", "transcript.py") and path.parent.name == "protocol":
            continue  # the tables, and the text format's own grammar (its SUFFIX)
        for node in ast.walk(parsed(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, (str, bytes)):
                value = node.value if isinstance(node.value, str) else node.value.decode("latin-1")
                found += [f"{name_of(path)}:{node.lineno}: {value!r}" for n in named if n == value]
    assert not found, "\n".join(found)
