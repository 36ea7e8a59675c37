#!/usr/bin/env python3
# Störmer–Verlet (kick–drift–kick) as a geomint `exec:` process speaking JSON lines: the
# protocol of docs/PYTHON.md, "Integrators in any language: exec:", in plain Python (no numpy).
# Run:  geomint run --problem kepler --method "exec:cmd=python3 examples/exec/verlet.py"
import json
import sys


def send(message):
    sys.stdout.write(json.dumps(message) + "\n")
    sys.stdout.flush()


def receive():
    line = sys.stdin.readline()
    if not line:  # geomint closed the pipe: the run is over
        sys.exit(0)
    return json.loads(line)


def gradient(q):
    # ∇V comes from geomint's problem: ask, and read the answer.
    send({"grad": q})
    return receive()["grad"]


def hessian(q):
    # ∇²V(q), n×n row-major: only the linearised step (tangent) asks for it.
    send({"hessian": q})
    flat, n = receive()["hessian"], len(q)
    return [flat[i * n:(i + 1) * n] for i in range(n)]


def kick_tangent(block_q, block_p, H, c):
    # δp ← δp − c ∇²V δq, for each of the 2n tangent vectors (the columns of the blocks).
    n, columns = len(H), len(block_q[0])
    for i in range(n):
        for j in range(columns):
            block_p[i][j] -= c * sum(H[i][k] * block_q[k][j] for k in range(n))


send({"name": "verlet_py", "order": 2, "flags": ["explicit", "symplectic", "symmetric"],
      "tangent": True})
q = p = inverse_mass = None
g, g_at = None, None  # ∇V(q) of the last step, reused while q is unchanged (one gradient a step)
while True:
    command = receive()
    if command["cmd"] == "reset":
        q, p, inverse_mass = command["q"], command["p"], command["inverse_mass"]
        g, g_at = None, None
        send({"ok": True})
    elif command["cmd"] == "step":
        h = command["h"]
        if g_at != q:
            g = gradient(q)
        if command.get("tangent"):
            # DΦ = kick(∇²V(q⁺)) · drift · kick(∇²V(q)), pushed through the stages from (δq, δp) = I.
            n = len(q)
            block_q = [[1.0 if j == i else 0.0 for j in range(2 * n)] for i in range(n)]
            block_p = [[1.0 if j == n + i else 0.0 for j in range(2 * n)] for i in range(n)]
            kick_tangent(block_q, block_p, hessian(q), h / 2)
            for i in range(n):
                block_q[i] = [a + h * (inverse_mass[i] * b) for a, b in zip(block_q[i], block_p[i])]
        # The arithmetic of geomint's stormer_verlet, term by term, so the rows agree bit for bit.
        p = [pi - (h / 2) * gi for pi, gi in zip(p, g)]
        q = [qi + h * (mi * pi) for qi, mi, pi in zip(q, inverse_mass, p)]
        g = gradient(q)
        g_at = q
        p = [pi - (h / 2) * gi for pi, gi in zip(p, g)]
        if command.get("tangent"):
            kick_tangent(block_q, block_p, hessian(q), h / 2)
            send({"q": q, "p": p, "tangent": [x for row in block_q + block_p for x in row]})
        else:
            send({"q": q, "p": p})
    else:
        send({"error": "unknown command " + command["cmd"]})
