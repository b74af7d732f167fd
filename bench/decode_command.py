"""`appmode decode FILE` on a 10 MB board stream with 1 % noise, beside a plain Python
loop that reads the same file byte by byte, finds the same events
(tests/support/byte_loops.py's SameEventsByteLoop) and writes them with the same renderer: the
two outputs are byte-identical (checked: a run whose outputs differ is an error).

Both are timed as processes, start-up included, writing to a file.
Target: appmode at least 1.5x the loop.
"""

from __future__ import annotations

import argparse
import filecmp
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tests.support.byte_loops import make_stream

LOOP = r"""
import sys
sys.path.insert(0, sys.argv[2])
from tests.support.byte_loops import SameEventsByteLoop
from appmode.protocol.layouts import VELOCITY
from appmode.protocol.render import coalesce, json_line
loop = SameEventsByteLoop()
with open(sys.argv[1], "rb") as stream:
    while chunk := stream.read(65536):
        loop.feed(chunk)
loop.flush()
write = sys.stdout.write
for event in coalesce(loop.events):
    write(json_line(event, VELOCITY) + "\n")
"""


def timed(args: list[str], out: Path) -> float:
    start = time.perf_counter()
    with out.open("w") as sink:
        subprocess.run(args, stdout=sink, check=False)
    return time.perf_counter() - start


def compare(megabytes: float) -> dict[str, float]:
    """Seconds of each (the better of two runs), after checking identical output."""
    stream, _ = make_stream(int(megabytes * 1e6), 0.01)
    with tempfile.TemporaryDirectory() as tmp:
        path, mine, theirs = Path(tmp) / "stream.bin", Path(tmp) / "a", Path(tmp) / "b"
        path.write_bytes(stream)
        here = str(Path(__file__).parents[1])
        ours = min(
            timed([sys.executable, "-m", "appmode", "decode", str(path)], mine) for _ in range(2)
        )
        loop = min(timed([sys.executable, "-c", LOOP, str(path), here], theirs) for _ in range(2))
        if not filecmp.cmp(mine, theirs, shallow=False):
            raise SystemExit("the loop's output is not appmode decode's: the anchor is wrong")
        size = mine.stat().st_size
    return {
        "mb": len(stream) / 1e6,
        "ours": ours,
        "loop": loop,
        "speedup": loop / ours,
        "out_mb": size / 1e6,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--megabytes", type=float, default=10.0)
    r = compare(parser.parse_args().megabytes)
    print(f"{r['mb']:.1f} MB board stream, 1 % noise; both wrote the same {r['out_mb']:.1f} MB")
    print(f"appmode decode FILE        {r['ours']:6.2f} s  {r['mb'] / r['ours']:5.2f} MB/s")
    print(f"same events byte by byte   {r['loop']:6.2f} s  {r['mb'] / r['loop']:5.2f} MB/s")
    print(f"appmode {r['speedup']:.2f}x the loop (target >= 1.5x)")


if __name__ == "__main__":
    main()
