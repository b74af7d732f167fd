"""`appmode convert IN OUT`: a transcript as MCAP and back, losslessly — every line's
time, direction and bytes (or pattern), its directives and comments, and its line
number (MCAP's sequence number; blank lines put a line back at its number). The MCAP
file adds the decoded channels viewers plot; reading it back skips them."""

from __future__ import annotations

import os
import sys

from appmode.board.profiles import profile_named
from appmode.errors import AppmodeError
from appmode.files import check_writable, write_streamed
from appmode.protocol.formats import written_as
from appmode.transcript.dump import needs_of
from appmode.transcript.reading import iter_lines


def run_convert(source: str, output: str, profile: str | None, partial: bool) -> int:
    """Write `source` (a transcript or MCAP) to `output`, in the format its name's suffix
    chooses (`protocol.formats.WRITERS`: MCAP for `.mcap`, else a transcript); the decoded
    channels in `profile`'s terms (default: the source's `@board profile=…`)."""
    if _same_file(source, output):
        raise AppmodeError(f"convert: {output} is the file being read; name another output")
    check_writable(output, "the converted file")

    def warn(text: str) -> None:
        print(f"appmode: WARNING: {text}", file=sys.stderr)

    given = profile_named(profile) if profile else None  # a file the @board line may name
    needs = needs_of(source, lambda text: None, partial=partial)
    layout = (given or needs.profile).a_layout
    items = iter_lines(source, warn, partial=partial)
    form = written_as(output)
    counted: list[int] = []
    write_streamed(output, form.convert(items, layout, needs.drive, counted), "the converted file")
    print(
        f"convert: {len(counted)} lines of {source} written to {output} ({form.name})",
        file=sys.stderr,
    )
    return 0


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False
