"""`appmode decode FILE` on a 10 MB board stream with 1 % noise, beside a plain Python
loop that reads the same file byte by byte and writes the same JSON objects for the
records it finds (bench/decoder.py's firmware-style decoder, then json.dumps each).

Both write to /dev/null; both are timed as processes, start-up included.
Target: appmode at least 1.5x the loop.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import decoder

LOOP = r"""
import json, sys
sys.path.insert(0, sys.argv[2])
import decoder
from appmode.protocol.render import to_json
out = sys.stdout
d = decoder.ByteAtATime()
with open(sys.argv[1], "rb") as stream:
    while chunk := stream.read(65536):
        d.feed(chunk)
        for record in d.records:
            out.write(json.dumps(to_json(record), ensure_ascii=False) + "\n")
        d.records.clear()
"""


def timed(args: list[str]) -> float:
    start = time.perf_counter()
    with open("/dev/null", "w") as null:
        subprocess.run(args, stdout=null, check=True)
    return time.perf_counter() - start


def compare(megabytes: float) -> dict[str, float]:
    stream, _ = decoder.make_stream(int(megabytes * 1e6), 0.01)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "stream.bin"
        path.write_bytes(stream)
        here = str(Path(__file__).parent)
        ours = min(timed([sys.executable, "-m", "appmode", "decode", str(path)]) for _ in range(2))
        loop = min(timed([sys.executable, "-c", LOOP, str(path), here]) for _ in range(2))
    return {"mb": len(stream) / 1e6, "ours": ours, "loop": loop, "speedup": loop / ours}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--megabytes", type=float, default=10.0)
    r = compare(parser.parse_args().megabytes)
    print(f"{r['mb']:.1f} MB board stream, 1 % noise, to /dev/null")
    print(f"appmode decode FILE        {r['ours']:6.2f} s  {r['mb'] / r['ours']:5.2f} MB/s")
    print(f"byte loop + json.dumps     {r['loop']:6.2f} s  {r['mb'] / r['loop']:5.2f} MB/s")
    print(f"appmode {r['speedup']:.2f}x the loop (target >= 1.5x)")


if __name__ == "__main__":
    main()
