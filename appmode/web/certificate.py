"""HTTPS for a page served beyond this machine: browsers give the tilt sensor and the
Gamepad API only to secure pages, and `http://192.168.1.20:8080` is not one.

A self-signed certificate for this machine's names and addresses is made on first use
(with `cryptography`) and kept in appmode's data folder; its fingerprint is printed with
the address, so the owner can check what the phone's browser shows before accepting it.
"""

from __future__ import annotations

import datetime
import hashlib
import ipaddress
import os
import socket
import ssl
import sys
from pathlib import Path

from appmode.errors import AppmodeError
from appmode.files import data_folder, temporary_beside

SERVERS = {"web": "the page", "share": "the share"}
"""The servers that keep a certificate of their own (`NAME-cert.pem`, `NAME-key.pem`), and
what each is called: a new one for the page must not break the share's clients' `ca=`."""
DAYS = 825
"""How long a made certificate is valid (the longest some browsers accept)."""


def machine_names(listen: str) -> list[str]:
    """The names and addresses a browser may reach this server by: the address it
    listens on, or for a wildcard (`0.0.0.0`, `::`) this machine's name and addresses."""
    names = {"localhost", "127.0.0.1"}
    if listen not in ("0.0.0.0", "::", ""):
        names.add(listen)
        return sorted(names)
    hostname = socket.gethostname()
    names |= {hostname, f"{hostname}.local", *lan_addresses(ipv6=listen != "0.0.0.0")}
    try:
        for *_, address in socket.getaddrinfo(hostname, None):
            names.add(str(address[0]).split("%")[0])
    except OSError:
        pass
    return sorted(names)


def lan_addresses(ipv6: bool) -> list[str]:
    """This machine's addresses on its networks, interface by interface (up, not
    loopback; no link-local IPv6, which a URL cannot use without the phone's zone)."""
    import psutil  # every platform's interfaces: the standard library lists none

    up = {name for name, stats in psutil.net_if_stats().items() if stats.isup}
    found = []
    for name, addresses in psutil.net_if_addrs().items():
        for entry in addresses if name in up else ():
            if entry.family not in (socket.AF_INET, socket.AF_INET6):
                continue
            if entry.family == socket.AF_INET6 and not ipv6:
                continue
            address = ipaddress.ip_address(entry.address.split("%")[0])
            if not (address.is_loopback or address.is_link_local or address.is_unspecified):
                found.append(str(address))
    return found


def _san(names: list[str]) -> list[object]:
    from cryptography import x509

    entries: list[object] = []
    for name in names:
        try:
            entries.append(x509.IPAddress(ipaddress.ip_address(name)))
        except ValueError:
            entries.append(x509.DNSName(name))
    return entries


def _why_new(cert_path: Path, names: list[str]) -> str | None:
    """Why the certificate kept there will not do (None: it is valid now and names
    every one of `names`); "" when none is kept."""
    from cryptography import x509

    if not cert_path.exists():
        return ""
    try:
        if not cert_path.is_file():  # a FIFO would hang the read
            raise ValueError("not a regular file")
        cert = x509.load_pem_x509_certificate(cert_path.read_bytes())
        held = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    except (OSError, ValueError, x509.ExtensionNotFound) as exc:
        return f"the one kept in {cert_path} could not be read ({exc})"
    now = datetime.datetime.now(datetime.timezone.utc)
    if not cert.not_valid_before_utc <= now < cert.not_valid_after_utc:
        return f"the one kept in {cert_path} is not valid now"
    missing = [name for name, entry in zip(names, _san(names), strict=True) if entry not in held]
    return f"the one kept does not name {', '.join(missing)}" if missing else None


def own_certificate(
    names: list[str], folder: Path | None = None, server: str = "web"
) -> tuple[Path, Path]:
    """appmode's certificate of `server` (`web`, `share`) for `names` (made, or made anew,
    when the one kept does not cover them): the certificate's path and its key's."""
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import NameOID

    folder = folder or data_folder()
    cert_path, key_path = folder / f"{server}-cert.pem", folder / f"{server}-key.pem"
    why = _why_new(cert_path, names) if key_path.is_file() else ""
    if why is None:
        return cert_path, key_path
    if why:
        print(
            f"appmode: made a new certificate for {SERVERS[server]}: {why}; its fingerprint "
            "is new, so "
            + ("the browser asks again" if server == "web" else "clients need it anew (ca=)"),
            file=sys.stderr,
        )
    key = ec.generate_private_key(ec.SECP256R1())
    subject = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, f"appmode {server}")])
    now = datetime.datetime.now(datetime.timezone.utc)
    cert = (
        x509.CertificateBuilder()
        .subject_name(subject)
        .issuer_name(subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=DAYS))
        .add_extension(x509.SubjectAlternativeName(_san(names)), critical=False)  # type: ignore[arg-type]
        .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
        .sign(key, hashes.SHA256())
    )
    key_bytes = key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    )
    try:
        folder.mkdir(parents=True, exist_ok=True)
        _write(key_path, key_bytes, 0o600)
        _write(cert_path, cert.public_bytes(serialization.Encoding.PEM), 0o644)
    except OSError as exc:
        raise AppmodeError(
            f"cannot keep the page's certificate in {folder}: {exc.strerror or exc}; "
            "give your own with --cert FILE --key FILE"
        ) from None
    return cert_path, key_path


def _write(path: Path, data: bytes, mode: int) -> None:
    """Write whole or not at all (a temporary file beside it, then renamed)."""
    tmp = temporary_beside(path)
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def server_context(cert: Path, key: Path) -> ssl.SSLContext:
    """A TLS context serving `cert`; a clear error for files that are not a pair."""
    context = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
    for path in (cert, key):
        if path.exists() and not path.is_file():  # a FIFO would hang the read
            raise AppmodeError(f"cannot serve HTTPS with {path}: it is not a file; give a PEM file")
    try:
        context.load_cert_chain(cert, key)
    except (OSError, ssl.SSLError) as exc:
        raise AppmodeError(
            f"cannot serve HTTPS with {cert} and {key}: {getattr(exc, 'strerror', None) or exc}; "
            "give a PEM certificate and its key"
        ) from None
    return context


def grouped(fingerprint: str) -> list[str]:
    """A fingerprint (AB:CD:…) in lines of 16 bytes, each in two groups of 8, as a person
    compares it with what a browser shows."""
    pairs = fingerprint.split(":")
    return [
        "  ".join(":".join(pairs[i + j : i + j + 8]) for j in (0, 8) if pairs[i + j : i + j + 8])
        for i in range(0, len(pairs), 16)
    ]


def fingerprint(cert: Path) -> str:
    """The certificate's SHA-256 fingerprint, as browsers show it (AB:CD:…)."""
    der = ssl.PEM_cert_to_DER_cert(cert.read_text(encoding="ascii"))
    digest = hashlib.sha256(der).hexdigest().upper()
    return ":".join(digest[i : i + 2] for i in range(0, len(digest), 2))
