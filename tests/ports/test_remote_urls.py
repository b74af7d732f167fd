"""A shared car's URL (`zenoh://NAME?key=…`) as the commands read it: every message that
quotes it hides the key (issue 80.12: four errors printed it), and an option given twice
is refused rather than the last taken."""

from __future__ import annotations

import pytest

from appmode.errors import AppmodeError
from appmode.ports.target import parse_target
from tests.support.processes import run

SECRET = "s3cret-key"


@pytest.mark.parametrize(
    ("url", "said"),
    [
        (f"zenoh://car?key={SECRET}&port=x", "port='x'"),
        (f"zenoh://car?key={SECRET}&bogus=1", "unknown option 'bogus'"),
        (f"zenoh://c%20ar?key={SECRET}", "is not a car's name"),
        (f"zenoh://car?key={SECRET}&take=2", "take='2'"),
        (f"zenoh://car?key=other&key={SECRET}", "key= twice"),
        (f"zenoh://car?connect=tcp/a:1&connect=tcp/b:2&key={SECRET}", "connect= twice"),
    ],
)
def test_a_shared_car_s_url_errors_hide_its_key(url: str, said: str) -> None:
    with pytest.raises(AppmodeError) as caught:
        parse_target(url)
    assert said in str(caught.value) and SECRET not in str(caught.value)
    assert "key=…" in str(caught.value)


def test_the_command_line_hides_the_key_too() -> None:
    done = run("send", f"zenoh://car?key={SECRET}&take=2", "J", timeout=30)
    assert done.returncode == 2 and "take='2'" in done.stderr
    assert SECRET not in done.stderr + done.stdout
