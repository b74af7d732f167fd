"""`appmode web` beyond loopback: HTTPS with appmode's own certificate (its fingerprint
printed, kept for the next start) or the user's, the Host check on a wildcard address,
and the page driving over wss in Chromium."""

from __future__ import annotations

import hashlib
import re
import ssl
import stat
from pathlib import Path

from cryptography import x509
from playwright.sync_api import Browser

from tests.support.processes import run
from tests.support.web import WebProcess, wait_sent, web_process
from tests.web.test_page import browser  # noqa: F401  (the fixture)
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
            printed = re.search(r"fingerprint is ([0-9A-F:]{95})", err)
            assert printed and printed.group(1) == served, err
            assert "WARNING: the page is served on 0.0.0.0" in err
            names = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
            assert "127.0.0.1" in [str(ip) for ip in names.get_values_for_type(x509.IPAddress)]
            prints.append(served)
    assert prints[0] == prints[1], "the certificate is kept for the next start"
    key = tmp_path / "data" / "appmode" / "web-key.pem"
    assert stat.S_IMODE(key.stat().st_mode) == 0o600


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


def test_the_page_drives_over_https(browser: Browser, tmp_path: Path) -> None:  # noqa: F811
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
