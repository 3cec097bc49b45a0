"""What the tests of ``rig serve scope`` share: the server as a subprocess (``Served``), the
resource of a transport among a server's (``resource``), a pyvisa client of one
(``open_scope``) and a tap that records what a client library sends over a raw socket (``Tap``)."""
import os
import signal
import socket
import subprocess
import sys
import threading

from instruments.transports.tcp import TcpService

RIG = [sys.executable, "-m", "rig.cli"]


class Served:
    """A ``rig serve scope`` process: its resources (from the "listening" line) and output."""

    def __init__(self, *args: str):
        self.proc = subprocess.Popen([*RIG, "serve", "scope", *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True, env=os.environ | {"PYTHONUNBUFFERED": "1"})
        self.lines = []
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))
            if line.startswith("listening"):
                break
        else:
            raise AssertionError("rig serve ended before listening:\n" + "\n".join(self.lines))
        self.resources = self.lines[-1].split(": ", 1)[1].split("  ")

    def resource(self, kind: str) -> str:
        return resource(self.resources, kind)

    def port(self) -> int:
        """The raw socket's port (the next to last field: an IPv6 address holds '::' too)."""
        return int(self.resource("SOCKET").split("::")[-2])

    def stop(self) -> tuple:
        self.proc.send_signal(signal.SIGTERM)
        rest, _ = self.proc.communicate(timeout=30)
        return self.proc.returncode, rest


def resource(resources: list, kind: str) -> str:
    """The first of a server's ``resources`` naming ``kind`` ("SOCKET", "hislip0", ...)."""
    return next(r for r in resources if kind in r)


def open_scope(rm, resource: str):
    """A pyvisa client of ``resource`` (a raw socket's messages end in a newline)."""
    inst = rm.open_resource(resource, timeout=60_000)
    if resource.endswith("SOCKET"):
        inst.read_termination = inst.write_termination = "\n"
    return inst


class Tap:
    """A TCP relay in front of a raw-socket server (127.0.0.1:``port``) that keeps every
    message its clients send (newline-framed, as the socket server reads them), so a test
    can say what a client library sent; the replies pass untouched."""

    def __init__(self, port: int):
        self.target = port
        self.sent: list = []
        self._service = TcpService(self._relay, name="tap").start()
        self.port = self._service.port

    def messages(self) -> list:
        """The messages sent so far, as text without their newline."""
        return [m.decode("latin-1") for m in b"".join(self.sent).split(b"\n") if m]

    def _relay(self, client: socket.socket, peer: str) -> None:
        with socket.create_connection(("127.0.0.1", self.target)) as server:
            back = threading.Thread(target=_pump, args=(server, client, None), daemon=True)
            back.start()
            _pump(client, server, self.sent)
            server.shutdown(socket.SHUT_WR)
            back.join(5)

    def close(self) -> None:
        self._service.close()


def _pump(src: socket.socket, dst: socket.socket, keep) -> None:
    """Copy ``src`` to ``dst`` until ``src`` ends (appending each chunk to ``keep``)."""
    try:
        while chunk := src.recv(1 << 16):
            if keep is not None:
                keep.append(chunk)
            dst.sendall(chunk)
    except OSError:
        pass
