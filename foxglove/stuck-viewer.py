#!/usr/bin/env python3
"""A live-view client that subscribes to every channel and never reads.

The worst viewer a run can have: the server's queue for it fills and the
oldest messages are dropped. Used to check that such a client does not cost
the run deadlines (README, "Watch a run in Foxglove"):

    python3 foxglove/stuck-viewer.py 127.0.0.1:8765 &
    testbed run --live --live-rate 1000 --duration 20 --json

Standard library only: a WebSocket handshake, one subscribe frame, then
silence until the server closes the connection or the script is killed.
"""

import base64
import json
import os
import socket
import sys
import time


def frame(text: str) -> bytes:
    """One masked text frame (clients must mask)."""
    data = text.encode()
    mask = os.urandom(4)
    n = len(data)
    if n < 126:
        head = bytes([0x81, 0x80 | n])
    elif n < 1 << 16:
        head = bytes([0x81, 0x80 | 126]) + n.to_bytes(2, "big")
    else:
        head = bytes([0x81, 0x80 | 127]) + n.to_bytes(8, "big")
    return head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data))


def read_frame(sock: socket.socket) -> bytes:
    def exact(n: int) -> bytes:
        buf = b""
        while len(buf) < n:
            chunk = sock.recv(n - len(buf))
            if not chunk:
                raise ConnectionError("the server closed the connection")
            buf += chunk
        return buf

    b0, b1 = exact(2)
    n = b1 & 0x7F
    if n == 126:
        n = int.from_bytes(exact(2), "big")
    elif n == 127:
        n = int.from_bytes(exact(8), "big")
    return exact(n)


def connect(addr: str, deadline_s: float = 60.0) -> socket.socket:
    host, port = addr.rsplit(":", 1)
    start = time.monotonic()
    while True:
        try:
            sock = socket.create_connection((host, int(port)))
            break
        except OSError:
            if time.monotonic() - start > deadline_s:
                sys.exit(f"stuck-viewer: nobody listens on {addr}")
            time.sleep(0.01)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: {addr}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
            "Sec-WebSocket-Version: 13\r\n"
            "Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n"
        ).encode()
    )
    response = b""
    while b"\r\n\r\n" not in response:
        response += sock.recv(1)
    if b" 101 " not in response.split(b"\r\n")[0]:
        sys.exit(f"stuck-viewer: handshake refused: {response!r}")
    return sock


def main() -> None:
    addr = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:8765"
    sock = connect(addr)
    while True:
        msg = json.loads(read_frame(sock))
        if msg.get("op") == "advertise":
            break
    subs = [{"id": i + 1, "channelId": c["id"]} for i, c in enumerate(msg["channels"])]
    sock.sendall(frame(json.dumps({"op": "subscribe", "subscriptions": subs})))
    print(f"stuck-viewer: subscribed to {len(subs)} channels; reading nothing", flush=True)
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
