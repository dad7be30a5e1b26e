#!/usr/bin/python3
"""scripts/reference-robot-server (docs/robot-protocol.md) against its rules and against selfcal, on loopback.

  reference_server_test.py MODE SELFCAL SOURCE_DIR

Modes (each a ctest of its own):
  protocol    raw requests: JOINTS before HELLO refused, a second client refused while the first goes on,
              bad MOVEs refused, and a connection reset (RST) by the client mid-move: the arm at rest within
              one control cycle (from the server's log), and still there for the next client.
  session     selfcal run --backend network --camera sim: the default plan (25 poses) recorded while a second
              client is refused mid-session, calibrate accepts it.
  kill        selfcal SIGKILLed mid-move: the arm at rest within one control cycle of the server noticing,
              measured from the kill.
  exception   the arm's joint read raises mid-move: the server stops the arm (within a cycle) and drops the
              client; selfcal halts (exit 4) and sends no motion command after it.
  protective  a protective stop mid-move: selfcal halts (exit 4), no MOVE after it; refused again until a
              person acknowledges (SIGUSR1), then `run --resume` completes the session.
  emergency   an emergency stop mid-move: selfcal halts (exit 4), no MOVE after it.
  terminate   the server ended (SIGTERM) mid-move: the arm at rest within a cycle, selfcal halts (exit 4).
"""
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rehearsal_test  # noqa: E402  (run_mode)

PLAN = "config/trajectories/initial_puma560.yaml"
CYCLE_S = 0.008


STARTED = []  # every server a test started: stopped at the end whatever happened


class Server:
    """The reference server on a free port; its stderr collected line by line with the arrival time."""

    def __init__(self, src, extra=()):
        with open(os.path.join(src, PLAN)) as f:
            first = yaml.safe_load(f)["poses_rad"][0]
        args = [sys.executable, os.path.join(src, "scripts", "reference-robot-server"), "--port", "0",
                "--cycle-s", str(CYCLE_S), "--initial-joints-rad", ",".join(repr(q) for q in first)] + list(extra)
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        STARTED.append(self.proc)
        line = self.proc.stdout.readline()
        if not line.startswith("listening on 127.0.0.1:"):
            raise RuntimeError("reference-robot-server did not start: " + line + self.proc.stderr.read())
        self.port = int(line.strip().rsplit(":", 1)[1])
        self.lines = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stderr:
            self.lines.append(line.rstrip("\n"))

    def log(self):
        return "\n".join(self.lines)

    def wait_for(self, pattern, timeout_s=30.0):
        """The first log line matching `pattern` (regex), waiting for it."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            for line in list(self.lines):
                if re.search(pattern, line):
                    return line
            time.sleep(0.005)
        raise AssertionError("no log line matches %r:\n%s" % (pattern, self.log()))

    def moves_started(self):
        return sum(1 for line in self.lines if re.search(r"move #\d+ started", line))

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        self.proc.wait(timeout=10)
        self.reader.join(timeout=5)
        return self.log()


def check_rest(server, failures, what, since_s=None):
    """The log's `arm at rest (client gone...)` line: at most one cycle after the stop request; returns it."""
    line = server.wait_for(r"arm at rest \(.*\): stopped in cycle")
    m = re.search(r"(\d+) cycle\(s\) after the stop request .* ([0-9.]+) s after it", line)
    cycles, latency = int(m.group(1)), float(m.group(2))
    t_rest = float(line.split()[0])
    measured = "" if since_s is None else ", %.2f ms after %s" % (1000 * (t_rest - since_s), what)
    print("%s: arm at rest %d cycle(s) after the stop request (%.2f ms; cycle %.1f ms)%s" %
          (what, cycles, 1000 * latency, 1000 * CYCLE_S, measured))
    if cycles > 1:
        failures.append("%s: the arm came to rest %d cycles after the stop request:\n%s" % (what, cycles, line))
    return t_rest


class Client:
    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=2)
        self.reader = self.sock.makefile("r", encoding="ascii", newline="\n")

    def ask(self, line):
        self.sock.sendall((line + "\n").encode("ascii"))
        return self.reader.readline().rstrip("\n")


def protocol(selfcal, src, tmp, failures):
    server = Server(src)
    a = Client(server.port)
    expect = [("JOINTS", "ERR bad_request send HELLO first"), ("MOVE 1 0 0 0 0 0 0", "ERR bad_request send HELLO first"),
              ("HELLO selfcal-robot 2", "ERR bad_request unsupported protocol"),
              ("HELLO selfcal-robot 1", "OK selfcal-robot 1 model=reference-sim serial=REF-0001 calibration= joints=6 real=0")]
    for request, reply in expect:
        got = a.ask(request)
        if not got.startswith(reply):
            failures.append("%s: %r, expected %r" % (request, got, reply))
    b = Client(server.port)  # a second client while the first is connected
    got = b.reader.readline().rstrip("\n")
    if got != "ERR fault busy: another client is connected" or b.reader.readline() != "":
        failures.append("second client: %r, not refused and closed" % got)
    start = [float(v) for v in a.ask("JOINTS").split()[2:8]]
    for bad in ("MOVE 1 nan 0 0 0 0 0", "MOVE 0 " + " ".join(map(repr, start)), "MOVE 1 7 0 0 0 0 0", "MOVE 1 0 0"):
        got = a.ask(bad)
        if not got.startswith("ERR "):
            failures.append("%s accepted: %r" % (bad, got))
    target = list(start)
    target[0] += 0.5
    if a.ask("MOVE 1 " + " ".join(map(repr, target))) != "OK":
        failures.append("a valid MOVE refused")
    time.sleep(0.3)  # mid-move (0.9 s at 60 deg/s)
    if not a.ask("STATUS").startswith("OK moving"):
        failures.append("not moving after MOVE")
    # The client resets the connection (RST: SO_LINGER 0) mid-move.
    a.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    reset_s = time.monotonic()
    a.reader.close()  # the file holds the socket open
    a.sock.close()
    gone = server.wait_for(r"client gone \(connection (lost|closed)")
    print("server: " + gone)
    check_rest(server, failures, "connection reset", reset_s)
    time.sleep(0.2)
    c = Client(server.port)  # the arm stays where it stopped: not at the target, not moving
    c.ask("HELLO selfcal-robot 1")
    q1 = [float(v) for v in c.ask("JOINTS").split()[2:14]]
    time.sleep(0.1)
    q2 = [float(v) for v in c.ask("JOINTS").split()[2:14]]
    if q1 != q2 or any(q1[6:]) or abs(q1[0] - target[0]) < 0.05 or c.ask("STATUS") != "OK idle":
        failures.append("after the reset the arm moved on: %s then %s" % (q1, q2))
    if c.ask("BYE") != "OK" or c.reader.readline() != "":
        failures.append("BYE did not close the connection")
    server.stop()


def run_selfcal(selfcal, src, server, session, extra=(), background=False):
    args = [selfcal, "run", "--backend", "network", "--address", "127.0.0.1:%d" % server.port, "--camera", "sim",
            "--velocity-scaling", "1", "--live-view", "off", "--session", session] + list(extra)
    if background:
        return subprocess.Popen(args, cwd=src, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    p = subprocess.run(args, cwd=src, capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout + p.stderr


def session(selfcal, src, tmp, failures):
    server = Server(src)
    s = os.path.join(tmp, "s")
    proc = run_selfcal(selfcal, src, server, s, background=True)
    server.wait_for(r"move #5 started")
    intruder = Client(server.port)  # a second client mid-session: refused, the session goes on
    refused = intruder.reader.readline().rstrip("\n")
    if refused != "ERR fault busy: another client is connected" or intruder.reader.readline() != "":
        failures.append("a second client during the session: %r, not refused and closed" % refused)
    out, _ = proc.communicate(timeout=300)
    code = proc.returncode
    print(out[-800:])
    if code != 0 or "run: completed: session complete: 25 samples accepted" not in out:
        failures.append("run against the reference server: exit %d\n%s\n%s" % (code, out[-3000:], server.log()[-3000:]))
    log = server.stop()
    if "client gone (BYE)" not in log and "client gone (connection closed by the client (EOF))" not in log:
        failures.append("the server did not see the client leave:\n" + log[-2000:])
    if code != 0:
        return
    p = subprocess.run([selfcal, "calibrate", s, "--out", os.path.join(tmp, "cal"), "--no-html"], cwd=src,
                       capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        failures.append("calibrate: exit %d\n%s" % (p.returncode, (p.stdout + p.stderr)[-3000:]))


def halted_run(selfcal, src, tmp, failures, extra, expect_text):
    """A run that a server fault halts: exit 4, the text, and no MOVE after the fault's."""
    server = Server(src, extra)
    code, out = run_selfcal(selfcal, src, server, os.path.join(tmp, "s"))
    moves = server.moves_started()
    print(out[-1200:])
    if code != 4 or expect_text not in out or "HALTED" not in out:
        failures.append("expected exit 4 and %r: exit %d\n%s" % (expect_text, code, out[-3000:]))
    if moves != 3:  # moves #0, #1 and #2, the faulted one; none after it
        failures.append("%d moves reached the server, expected 3 (none after the fault)\n%s" % (moves, server.log()))
    return server, code, out


def mid_move(selfcal, src, tmp, move, act, attempts=3):
    """A run in the background until move #`move` is under way, then act(server, run process); returns
    the server, the run process and the time of the act (CLOCK_MONOTONIC). A move lasts 0.15-0.25 s: on a
    loaded machine the act can land after it ended (the server's stop line then says "the arm at rest"),
    which tests nothing, so the run is made again, in a new session, up to `attempts` times."""
    for attempt in range(attempts):
        server = Server(src)
        proc = run_selfcal(selfcal, src, server, os.path.join(tmp, "s%d" % attempt), background=True)
        server.wait_for(r"move #%d started" % move)
        time.sleep(0.05)
        acted_s = time.monotonic()
        act(server, proc)
        stop = server.wait_for(r"stop requested")
        if "the arm at rest" not in stop or attempt + 1 == attempts:
            return server, proc, acted_s
        print("attempt %d: the act came after move #%d had ended (%s); again" % (attempt + 1, move, stop))
        proc.kill()
        proc.wait()
        server.stop()


def emergency(selfcal, src, tmp, failures):
    server, _, _ = halted_run(selfcal, src, tmp, failures, ["--emergency-stop-move", "2"], "emergency_stop")
    server.stop()


def kill(selfcal, src, tmp, failures):
    # SIGKILL: the client's socket closed by the kernel mid-move
    server, proc, killed_s = mid_move(selfcal, src, tmp, 3, lambda server, proc: proc.kill())
    proc.wait()
    print("server: " + server.wait_for(r"client gone"))
    check_rest(server, failures, "selfcal killed", killed_s)
    if server.moves_started() != 4:
        failures.append("moves after the kill:\n" + server.log())
    server.stop()


def exception(selfcal, src, tmp, failures):
    server, _, _ = halted_run(selfcal, src, tmp, failures, ["--exception-move", "2"], "disconnected")
    log = server.stop()
    if "RuntimeError: injected fault" not in log or "client gone (exception in the server or the arm)" not in log:
        failures.append("the exception is not logged, or the client not dropped:\n" + log)
    check_rest(server, failures, "exception in the arm")


def protective(selfcal, src, tmp, failures):
    server, _, _ = halted_run(selfcal, src, tmp, failures, ["--protective-stop-move", "2"], "protective_stop")
    s = os.path.join(tmp, "s")
    code, out = run_selfcal(selfcal, src, server, s, ["--resume"])  # not acknowledged: refused, nothing moves
    if code != 4 or "protective_stop" not in out or server.moves_started() != 3:
        failures.append("a resume before the acknowledgement: exit %d, %d moves\n%s" %
                        (code, server.moves_started(), out[-2000:]))
    server.proc.send_signal(signal.SIGUSR1)  # a person acknowledges the stop at the controller
    server.wait_for(r"protective_stop acknowledged by a person")
    code, out = run_selfcal(selfcal, src, server, s, ["--resume"])
    print(out[-600:])
    if code != 0 or "run: completed: session complete" not in out:
        failures.append("the resume after the acknowledgement: exit %d\n%s" % (code, out[-3000:]))
    server.stop()


def terminate(selfcal, src, tmp, failures):
    server, proc, ended_s = mid_move(selfcal, src, tmp, 2,
                                     lambda server, proc: server.proc.send_signal(signal.SIGTERM))
    out, _ = proc.communicate(timeout=60)
    server.stop()
    check_rest(server, failures, "server terminated", ended_s)
    print(out[-600:])
    if proc.returncode != 4 or "HALTED" not in out:
        failures.append("selfcal after the server ended: exit %d\n%s" % (proc.returncode, out[-3000:]))


def main():
    mode, selfcal, src = sys.argv[1:4]
    body = {"protocol": protocol, "session": session, "kill": kill, "exception": exception,
            "protective": protective, "emergency": emergency, "terminate": terminate}[mode]
    return rehearsal_test.run_mode("refserver-", lambda tmp, failures: body(selfcal, src, tmp, failures), STARTED)


if __name__ == "__main__":
    sys.exit(main())
