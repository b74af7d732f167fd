"""Shared helpers live in tests/support/: decoders fed whole, split and byte by byte
(decoders.py), appmode run as a process and boards served by one (processes.py), and an
RFC 2217 server (rfc2217_server.py)."""
