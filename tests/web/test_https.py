"""`appmode web` beyond loopback: HTTPS with appmode's own certificate (its fingerprint
printed, kept for the next start) or the user's, the Host check on a wildcard address,
and the page driving over wss in Chromium."""

from __future__ import annotations

import hashlib
import re
import ssl
import stat
from pathlib import Path
from urllib.parse import urlsplit

from cryptography import x509
from playwright.sync_api import Browser

from tests.support.processes import run
from tests.support.web import WebProcess, wait_sent, web_process
from tests.web.test_server import get


def served_fingerprint(web: WebProcess) -> tuple[str, x509.Certificate]:
    port = int(web.origin.rsplit(":", 1)[1])
    pem = ssl.get_server_certificate(("127.0.0.1", port))
    digest = hashlib.sha256(ssl.PEM_cert_to_DER_cert(pem)).hexdigest().upper()
    text = ":".join(digest[i : i + 2] for i in range(0, len(digest), 2))
    return text, x509.load_pem_x509_certificate(pem.encode())


def local(web: WebProcess) -> str:
    """The page's origin by this machine's loopback address."""
    return "https://127.0.0.1:" + web.origin.rsplit(":", 1)[1]


def insecure() -> ssl.SSLContext:
    context = ssl.create_default_context()
    context.check_hostname = False
    context.verify_mode = ssl.CERT_NONE
    return context


def test_a_wildcard_address_is_served_over_https_with_a_checked_fingerprint(
    tmp_path: Path,
) -> None:
    prints = []
    for _ in range(2):
        with web_process(tmp_path, "--listen", "0.0.0.0:0") as web:
            assert web.address.startswith("https://")
            served, cert = served_fingerprint(web)
            code, err = web.stop()
            assert code == 0, err
            printed = re.search(r"fingerprint is\n((?:appmode:   [0-9A-F: ]+\n){2})", err)
            assert printed, err
            lines = printed.group(1).replace("appmode:", "").split()
            assert [len(group) for group in lines] == [23] * 4, "two lines of 2 x 8 bytes"
            assert ":".join(lines) == served
            assert "WARNING: the page is served on 0.0.0.0" in err
            names = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
            assert "127.0.0.1" in [str(ip) for ip in names.get_values_for_type(x509.IPAddress)]
            prints.append(served)
    assert prints[0] == prints[1], "the certificate is kept for the next start"
    key = tmp_path / "data" / "appmode" / "web-key.pem"
    assert stat.S_IMODE(key.stat().st_mode) == 0o600


def test_a_wildcard_address_prints_every_lan_address_and_a_qr_code_of_the_first(
    tmp_path: Path,
) -> None:
    import segno

    from appmode.web.certificate import lan_addresses

    with web_process(tmp_path, "--listen", "0.0.0.0:0") as web:
        code, err = web.stop()
    assert code == 0, err
    port = web.origin.rsplit(":", 1)[1]
    shown = [web.address, *re.findall(r"also at (\S+)", err)]
    hosts = [str(urlsplit(url).hostname) for url in shown]
    lan = lan_addresses(ipv6=False)
    assert set(lan) <= set(hosts), "every address of the machine's networks"
    assert all(":" not in host for host in hosts), "0.0.0.0 is IPv4 only"
    if lan:
        assert hosts[0] in lan, "an address a phone reaches comes first, not a name"
    assert all(url.endswith(f":{port}/?token={web.token}") for url in shown)
    art = err.split("scan:\n", 1)[1].split("\nappmode:", 1)[0].splitlines()
    rows = []  # two rows of modules a line: upper and lower half of each character
    for line in art:
        rows.append([c in "█▀" for c in line])
        rows.append([c in "█▄" for c in line])
    modules = [[not light for light in row[2:-2]] for row in rows[2:-2]][: len(rows[0]) - 4]
    expected = segno.make(shown[0], error="l").matrix
    assert modules == [[bool(m) for m in row] for row in expected], "the QR code is the first URL's"


def test_on_a_wildcard_address_the_host_must_be_an_address_or_this_machine(
    tmp_path: Path,
) -> None:
    with web_process(tmp_path, "--listen", "0.0.0.0:0") as web:
        port = web.origin.rsplit(":", 1)[1]
        address = local(web) + f"/?token={web.token}"
        assert get(address, tls=insecure())[0] == 303
        rebound = {"Host": f"attacker.example:{port}"}
        assert get(address, rebound, insecure())[0] == 403
        assert get(local(web) + "/", tls=insecure())[0] == 403, "no token"


def test_the_page_drives_over_https(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path, "--listen", "0.0.0.0:0") as web:
        context = browser.new_context(ignore_https_errors=True)
        page = context.new_page()
        page.goto(local(web) + f"/?token={web.token}")
        page.get_by_text("parameters read").wait_for(timeout=10_000)
        assert page.evaluate("window.isSecureContext")
        page.keyboard.down("w")
        wait_sent(web, "A")
        page.keyboard.up("w")
        wait_sent(web, "Z")
        context.close()


def test_the_user_s_certificate_or_a_clear_error(tmp_path: Path) -> None:
    done = run("web", "--listen", "127.0.0.1:0", "--cert", str(tmp_path / "c.pem"))
    assert done.returncode == 2 and "--cert and --key go together" in done.stderr
    (tmp_path / "c.pem").write_text("not a certificate\n")
    (tmp_path / "k.pem").write_text("not a key\n")
    done = run(
        "web",
        "--listen",
        "127.0.0.1:0",
        "--cert",
        str(tmp_path / "c.pem"),
        "--key",
        str(tmp_path / "k.pem"),
    )
    assert done.returncode == 2 and "cannot serve HTTPS" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
