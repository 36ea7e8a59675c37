#!/usr/bin/env python3
# An `exec:` process that goes wrong on purpose, one way per MODE (argv[1]), after a correct
# handshake and reset and `steps` (argv[2], default 2) correct explicit Euler steps: what
# tests/exec/exec_test.cpp checks each failure row against.
import json
import os
import signal
import sys
import time

mode = sys.argv[1]
good_steps = int(sys.argv[2]) if len(sys.argv) > 2 else 2


def send(text):
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


if mode == "bad_handshake":
    send('{"name": "x", "order": 2, "flags": ["explicit", "constrained"]}')
    sys.exit(0)
if mode == "silent_handshake":
    time.sleep(60)
send('{"name": "misbehave", "order": 1, "flags": ["explicit"]}')
if mode.startswith("binary_"):
    # format=binary: frames [code, count, values] of native doubles; answers reset, then the
    # first step goes wrong.
    import struct

    def frame():
        header = sys.stdin.buffer.read(16)
        if len(header) < 16:  # geomint closed the pipe (the spec check's own start)
            sys.exit(0)
        code, count = struct.unpack("=2d", header)
        return code, struct.unpack("=%dd" % int(count), sys.stdin.buffer.read(8 * int(count)))

    def send_frame(code, values):
        sys.stdout.buffer.write(struct.pack("=%dd" % (2 + len(values)), code, len(values), *values))
        sys.stdout.buffer.flush()

    code, values = frame()
    n = (len(values) - 1) // 3
    send_frame(4, [])
    frame()
    if mode == "binary_wrong_size":
        send_frame(4, [0.0] * (2 * n + 1))
    elif mode == "binary_nan":
        send_frame(4, [float("nan")] * (2 * n))
    elif mode == "binary_text":
        send("this is not a frame, it is text")
    elif mode == "binary_bad_code":
        send_frame(9, [])
    time.sleep(60)
q = p = None
steps = 0
for line in sys.stdin:
    command = json.loads(line)
    if command["cmd"] == "reset":
        q, p = command["q"], command["p"]
        send('{"ok": true}')
        continue
    if steps >= good_steps:
        if mode == "die":
            sys.exit(3)
        if mode == "segv":
            os.kill(os.getpid(), signal.SIGSEGV)
        if mode == "hang":
            time.sleep(60)
        if mode == "malformed":
            send("this is not json")
            continue
        if mode == "wrong_size":
            send(json.dumps({"q": q + [0.0], "p": p}))
            continue
        if mode == "nan":
            send(json.dumps({"q": [float("nan")] * len(q), "p": p}))
            continue
        if mode == "close_stdin":
            # Stops reading, then asks for a gradient: geomint's reply meets a closed pipe.
            os.close(0)
            send(json.dumps({"grad": q}))
            time.sleep(60)
        if mode == "error":
            send('{"error": "step size too large for my scheme"}')
            continue
    h = command["h"]
    send(json.dumps({"grad": q}))
    g = json.loads(sys.stdin.readline())["grad"]
    q, p = [a + h * b for a, b in zip(q, p)], [a - h * b for a, b in zip(p, g)]
    send(json.dumps({"q": q, "p": p}))
    steps += 1
