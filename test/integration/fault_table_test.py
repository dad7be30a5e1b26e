#!/usr/bin/python3
"""Whole sessions and the fault table against the fakes: selfcal-ur-fake (docs/universal-robots.md),
scripts/reference-robot-server (docs/robot-protocol.md) and selfcal-fanuc-fake (docs/fanuc.md), on loopback,
with `--camera sim`.

  fault_table_test.py ur-session SELFCAL UR_FAKE SOURCE_DIR
  fault_table_test.py ur:FAULT|reference:FAULT|fanuc:FAULT SELFCAL UR_FAKE SOURCE_DIR [FANUC_FAKE]

ur-session: `run --backend ur` of the default plan (25 poses, seed 1) against the UR fake (the operator types the
  serial), then `calibrate`: accepted, and the figures equal those of the same plan and seed on `--backend sim`
  (rehearsal_test.compare_with_simulated: every free parameter and f_x within 4 combined standard deviations,
  the same free set, check distances below 0.5 mm RMS); the journal records the controller's identity (model,
  serial, factory calibration id) and session.json names the session.
BACKEND:FAULT: one row of the fault table. The fault is injected during move #2 (pose p02, the third); the
  run must halt with exit 4 (a killed selfcal: SIGKILL) and a message naming the cause, say truthfully
  whether its stop command reached the controller (counted there), send no motion command after the
  faulted one, and have recorded the samples of poses p00 and p01; then the fault is cleared as a person would (UR: the Dashboard's `unlock protective stop`; reference server: SIGUSR1, the
  acknowledgement at the controller; a server that ended: started again; FANUC: SIGUSR1, RESET at the
  teach pendant) and `run --resume` (the same command)
  completes the session: 25 samples, the samples recorded before the fault unchanged (none lost), and
  `calibrate` accepts it. The row is printed in the table's form (docs/universal-robots.md,
  docs/robot-protocol.md).
"""
import json
import math
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rehearsal_test  # noqa: E402  (the comparison with the simulated backend)
import reference_server_test  # noqa: E402  (the reference server, started and read)

PLAN = "config/trajectories/initial_puma560.yaml"
FAULT_MOVE = 2
UR_SERIAL = "20235500001"


class LoopbackFake:
    """A fake controller binary at the plan's first pose on free ports; its stdout collected line by line.
    `pattern` reads its ports from its first line (self.ports)."""

    def __init__(self, binary, src, extra, pattern):
        with open(os.path.join(src, PLAN)) as f:
            first = yaml.safe_load(f)["poses_rad"][0]
        start = ",".join(repr(math.degrees(q)) for q in first)
        self.proc = subprocess.Popen([binary, "--start-deg", start] + list(extra), stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        reference_server_test.STARTED.append(self.proc)
        line = self.proc.stdout.readline()
        m = re.match(pattern, line)
        if not m:
            raise RuntimeError("%s did not start: %s%s" % (os.path.basename(binary), line, self.proc.stdout.read()))
        self.ports = [int(v) for v in m.groups()]
        self.lines = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def wait_for_motion_command(self, count, timeout_s=60.0):
        deadline = time.monotonic() + timeout_s
        while self.motion_commands() < count:
            if time.monotonic() > deadline:
                raise AssertionError("fewer than %d motion commands reached the fake:\n%s" % (count, "\n".join(self.lines)))
            time.sleep(0.005)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        self.proc.wait(timeout=10)
        self.reader.join(timeout=5)
        return "\n".join(self.lines)


class UrFake(LoopbackFake):
    """selfcal-ur-fake: RTDE, secondary and Dashboard ports."""

    def __init__(self, binary, src, extra=()):
        super().__init__(binary, src, extra, r"listening on 127.0.0.1 rtde (\d+) secondary (\d+) dashboard (\d+)")
        self.rtde, self.secondary, self.dashboard = self.ports

    def robot_args(self):
        return ["--backend", "ur", "--address", "127.0.0.1", "--ur-ports",
                "%d,%d,%d" % (self.rtde, self.secondary, self.dashboard)]

    def motion_commands(self):
        return sum(1 for line in list(self.lines) if line.startswith("secondary: movej("))

    def stop_commands(self):
        return sum(1 for line in list(self.lines) if line.startswith(("secondary: stopj(", "dashboard: stop")))

    def dashboard_command(self, line):
        """What a person does at the pendant, through the Dashboard server: one command, its answer."""
        with socket.create_connection(("127.0.0.1", self.dashboard), timeout=2) as sock:
            reader = sock.makefile("r", encoding="ascii", newline="\n")
            reader.readline()  # the greeting
            sock.sendall((line + "\n").encode("ascii"))
            return reader.readline().rstrip("\n")


class FanucFake(LoopbackFake):
    """selfcal-fanuc-fake: its RMI connect port; every packet it received is a `session: ` line."""

    def __init__(self, binary, src, extra=()):
        super().__init__(binary, src, extra, r"listening on 127.0.0.1:(\d+) ")
        self.port = self.ports[0]
        # RMI reports no serial: the operator arms the run by typing the controller's address instead.
        self.confirmation = "127.0.0.1:%d" % self.port

    def robot_args(self):
        return ["--backend", "fanuc", "--address", "127.0.0.1:%d" % self.port]

    def _packets(self, name):
        return sum(1 for line in list(self.lines) if line.startswith("session: ") and '"%s"' % name in line)

    def motion_commands(self):
        return self._packets("FRC_JointMotionJRep")

    def stop_commands(self):
        return self._packets("FRC_Abort")


class ReferenceServer(reference_server_test.Server):
    """The reference server at the plan's first pose (reference_server_test.Server), counted like the fake."""

    def robot_args(self):
        return ["--backend", "network", "--address", "127.0.0.1:%d" % self.port]

    def motion_commands(self):
        return self.moves_started()

    def stop_commands(self):
        return sum(1 for line in list(self.lines) if "stop requested (STOP request)" in line)

    def wait_for_motion_command(self, count, timeout_s=60.0):
        self.wait_for(r"move #%d started" % (count - 1), timeout_s)


def selfcal_args(selfcal, robot, session, extra=()):
    return [selfcal, "run"] + robot.robot_args() + ["--camera", "sim", "--velocity-scaling", "1", "--seed", "1",
                                                    "--live-view", "off", "--session", session] + list(extra)


def typed(robot):
    """What the operator types to arm a real robot: its serial (the UR's), or what the controller asks for."""
    return getattr(robot, "confirmation", UR_SERIAL)


def run(selfcal, src, robot, session, extra=()):
    """A run to its end; the operator types the UR's serial when asked (the reference server is not real)."""
    p = subprocess.run(selfcal_args(selfcal, robot, session, extra), cwd=src, input=typed(robot) + "\n",
                       capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout + p.stderr


def accepted_samples(session):
    """The journal's sample_accepted records, by pose."""
    return {r["pose"]: r for r in rehearsal_test.journal_records(session) if r.get("type") == "sample_accepted"}


def ur_session(selfcal, ur_fake, src, tmp, failures):
    fake = UrFake(ur_fake, src)
    session = os.path.join(tmp, "ur")
    code, out = run(selfcal, src, fake, session)
    log = fake.stop()
    print(out[-1200:])
    print(log.splitlines()[-1])
    if code != 0 or "run: completed: session complete: 25 samples accepted" not in out:
        failures.append("ur run with --camera sim: exit %d\n%s" % (code, out[-3000:]))
        return
    if "stopped; motion commands 25, stop commands 0" not in log:
        failures.append("the fake did not receive the 25 moves and no stop:\n" + log[-2000:])
    faults = rehearsal_test.journal_faults(session)
    print("faults recorded: %s" % faults)
    if faults:  # a reading is the next RTDE package, so a fault-free cell records none
        failures.append("a fault-free run recorded faults: %s" % faults)
    with open(os.path.join(session, "journal.log"), errors="replace") as f:
        started = json.loads(f.readline().split(" ", 3)[3])
    identity = {k: started.get(k) for k in ("robot_backend", "robot_model", "robot_serial", "robot_calibration")}
    print("recorded identity: %s" % identity)
    expected = {"robot_backend": "ur", "robot_model": "UR5e", "robot_serial": UR_SERIAL,
                "robot_calibration": "ur-kinematics-00001001-00001002-00001003-00001004-00001005-00001006"}
    if identity != expected:
        failures.append("the journal records %s, not the controller's %s" % (identity, expected))
    with open(os.path.join(session, "session.json")) as f:
        if json.load(f)["format"] != "selfcal-session":
            failures.append("session.json is not a session's")
    report = rehearsal_test.compare_with_simulated(selfcal, src, tmp, session, "ur", failures)
    if report is not None:
        print("verdict %s, %d samples" % (report["verdict"], report["session"]["samples_accepted"]))


# Each fault: the backend's options, how it is injected when not by an option, how a person clears it.
FAULTS = {
    "ur:drop": (["--drop-move", str(FAULT_MOVE)], None, None),
    "ur:protective": (["--protective-stop-move", str(FAULT_MOVE)], None, "unlock protective stop"),
    "ur:stall": (["--stall-move", str(FAULT_MOVE)], None, None),
    "ur:kill": ([], "kill selfcal", None),
    "reference:protective": (["--protective-stop-move", str(FAULT_MOVE)], None, "acknowledge"),
    "reference:emergency": (["--emergency-stop-move", str(FAULT_MOVE)], None, "acknowledge"),
    "reference:exception": (["--exception-move", str(FAULT_MOVE)], None, "acknowledge"),
    "reference:terminate": ([], "end the server", "start again"),
    "reference:kill": ([], "kill selfcal", None),
    "fanuc:drop": (["--drop-move", str(FAULT_MOVE)], None, None),
    "fanuc:servo-off": (["--servo-off-move", str(FAULT_MOVE)], None, "reset at the pendant"),
    "fanuc:stall": (["--stall-move", str(FAULT_MOVE)], None, None),
    "fanuc:wrong-answer": (["--wrong-answer-move", str(FAULT_MOVE)], None, None),
    "fanuc:kill": ([], "kill selfcal", "reset at the pendant"),  # its RMI session stays open
}
FANUC_FAKE = None  # the binary, from the command line


def start(kind, options, ur_fake, src):
    if kind.startswith("ur:"):
        return UrFake(ur_fake, src, options)
    if kind.startswith("fanuc:"):
        return FanucFake(FANUC_FAKE, src, options)
    return ReferenceServer(src, options)


def inject(selfcal, src, robot, session, act):
    """A run in the background until the faulted move is under way, then `act` (a kill: SIGKILL to selfcal,
    an end: SIGTERM to the server); returns its exit code and output."""
    proc = subprocess.Popen(selfcal_args(selfcal, robot, session), cwd=src, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    proc.stdin.write(typed(robot) + "\n")
    proc.stdin.close()
    robot.wait_for_motion_command(FAULT_MOVE + 1)  # the faulted move under way (a UR fake's takes 0.09 s)
    (proc if act == "kill selfcal" else robot.proc).send_signal(
        signal.SIGKILL if act == "kill selfcal" else signal.SIGTERM)
    out = proc.stdout.read()
    return proc.wait(timeout=120), out


def fault_row(kind, selfcal, ur_fake, src, tmp, failures):
    options, act, clear = FAULTS[kind]
    robot = start(kind, options, ur_fake, src)
    session = os.path.join(tmp, "s")
    if act is None:
        code, out = run(selfcal, src, robot, session)
    else:
        code, out = inject(selfcal, src, robot, session, act)
    sent, stops = robot.motion_commands(), robot.stop_commands()
    # The closing line says truthfully whether the stop went out (none reaches a controller that is gone).
    told = "The robot was told to stop." in out
    if act != "kill selfcal" and (told != (stops > 0) or (not told and "could not be sent" not in out)):
        failures.append("%s: %d stop commands reached the controller, and the run said:\n%s" % (kind, stops, out[-1500:]))
    halted = [line for line in out.splitlines() if line.startswith("run: halted")]
    printed = halted[0] if halted else "(killed: nothing printed)"
    before = accepted_samples(session) if os.path.exists(os.path.join(session, "journal.log")) else {}
    expected_code = -signal.SIGKILL if act == "kill selfcal" else 4
    if code != expected_code or (act != "kill selfcal" and not halted):
        failures.append("%s: exit %d (expected %d), or no `run: halted` line:\n%s" % (kind, code, expected_code, out[-3000:]))
    if sent != FAULT_MOVE + 1:
        failures.append("%s: %d motion commands reached the controller, expected %d (none after the fault)" %
                        (kind, sent, FAULT_MOVE + 1))
    if sorted(before) != list(range(FAULT_MOVE)):
        failures.append("%s: samples recorded before the fault: poses %s, expected 0..%d" % (kind, sorted(before), FAULT_MOVE - 1))
    resume = ["--resume"] + (["--take-over-stale-lock"] if act == "kill selfcal" else [])
    if clear in ("unlock protective stop", "acknowledge", "reset at the pendant"):  # nothing resumes by itself
        code_before, out_before = run(selfcal, src, robot, session, resume)
        if code_before != 4 or robot.motion_commands() != sent:
            failures.append("%s: a resume before the fault is cleared: exit %d, %d motion commands\n%s" %
                            (kind, code_before, robot.motion_commands() - sent, out_before[-2000:]))
    # The fault cleared as a person would; then the same command with --resume.
    if clear == "unlock protective stop":
        answer = robot.dashboard_command(clear)
        if answer != "Protective stop releasing":
            failures.append("%s: `unlock protective stop` answered %r" % (kind, answer))
    elif clear in ("acknowledge", "reset at the pendant"):
        robot.proc.send_signal(signal.SIGUSR1)
        time.sleep(0.3)
    elif clear == "start again":
        robot.stop()
        robot = start(kind, [], ur_fake, src)
    rcode, rout = run(selfcal, src, robot, session, resume)
    robot.stop()
    after = accepted_samples(session) if os.path.exists(os.path.join(session, "journal.log")) else {}
    lost = [pose for pose, record in before.items() if after.get(pose) != record]
    print(rout[-600:])
    if rcode != 0 or "run: completed: session complete" not in rout or len(after) != 25:
        failures.append("%s: the resume: exit %d, %d samples\n%s" % (kind, rcode, len(after), rout[-3000:]))
    if lost:
        failures.append("%s: samples recorded before the fault changed or lost: poses %s" % (kind, lost))
    verdict = "not calibrated"
    if rcode == 0:
        report = rehearsal_test.report_of(selfcal, src, session, os.path.join(tmp, "cal"), failures)
        verdict = "calibrate: %s" % (report["verdict"] if report else "failed")
        if report is not None and not report["accepted"]:
            failures.append("%s: calibrate after the resume: %s" % (kind, report["verdict"]))
    print("| fault | printed | exit | stop commands | motion commands after it | samples before / lost | `--resume` after clearing |")
    print("| %s | `%s` | %d | %d | %d | %d / %d | exit %d, %d samples, %s |" %
          (kind, printed[:200], code, stops, sent - (FAULT_MOVE + 1), len(before), len(lost), rcode, len(after), verdict))


def main():
    global FANUC_FAKE
    mode, selfcal, ur_fake, src = sys.argv[1:5]
    FANUC_FAKE = sys.argv[5] if len(sys.argv) > 5 else None
    if mode.startswith("fanuc:") and FANUC_FAKE is None:
        print("usage: fault_table_test.py fanuc:FAULT SELFCAL UR_FAKE SOURCE_DIR FANUC_FAKE", file=sys.stderr)
        return 2
    if mode == "ur-session":
        body = lambda tmp, failures: ur_session(selfcal, ur_fake, src, tmp, failures)  # noqa: E731
    else:
        body = lambda tmp, failures: fault_row(mode, selfcal, ur_fake, src, tmp, failures)  # noqa: E731
    return rehearsal_test.run_mode("faulttable-", body, reference_server_test.STARTED)


if __name__ == "__main__":
    sys.exit(main())
