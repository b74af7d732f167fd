"""A minimal RFC 2217 server over any pyserial port, after pyserial's rfc2217_server
example: lets the tests open `rfc2217://` against the simulated board."""

from __future__ import annotations

import socket
import threading

import serial
import serial.rfc2217


class Rfc2217Server:
    def __init__(self, port: serial.SerialBase) -> None:
        self.port = port
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.url = f"rfc2217://127.0.0.1:{self.listener.getsockname()[1]}"
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._accepter = threading.Thread(target=self._serve, daemon=True)
        self._accepter.start()

    def _serve(self) -> None:
        conn, _ = self.listener.accept()
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.conn = conn
        manager = serial.rfc2217.PortManager(self.port, self)
        reader = threading.Thread(target=self._to_network, args=(manager,), daemon=True)
        reader.start()
        self._threads.append(reader)
        conn.settimeout(0.1)
        while not self._stop.is_set():
            try:
                data = conn.recv(1024)
            except TimeoutError:
                continue
            except OSError:
                break
            if not data:
                break
            self.port.write(b"".join(manager.filter(data)))

    def write(self, data: bytes) -> None:  # PortManager sends its replies here
        self.conn.sendall(data)

    def _to_network(self, manager: serial.rfc2217.PortManager) -> None:
        while not self._stop.is_set():
            data = self.port.read(self.port.in_waiting or 1)
            if data:
                try:
                    self.conn.sendall(b"".join(manager.escape(data)))
                except OSError:
                    break

    def close(self) -> None:
        self._stop.set()
        for thread in [*self._threads, self._accepter]:
            thread.join(timeout=2)
        self.listener.close()
