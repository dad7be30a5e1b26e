#!/usr/bin/python3
"""Halts and refusals of real-cell backends through the command line, on loopback with `--camera sim`.

  network_halt_test.py never-settle|unconfirmed SELFCAL SELFCAL_ROBOT_SIM SELFCAL_UR_FAKE SOURCE_DIR

never-settle: selfcal-robot-sim whose arm keeps moving after move 2 (`--never-settle-move 2`: every joint
  reads 0.05 rad/s): `run --backend network --camera sim` halts at that pose (exit 4, the journal's halt names
  it), the controller has accepted 3 MOVEs and no other, the 2 samples before it are kept, and nothing
  says "complete".
unconfirmed: selfcal-ur-fake (a real arm to selfcal) and `run --backend ur --camera sim` with nothing typed
  at the confirmation (stdin empty): exit 2 (the operator's refusal, troubleshooting.md), no session
  created, 0 motion commands at the controller.
"""
import os
import re
import signal
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rehearsal_test  # noqa: E402  (run_mode: the loopback tests' temporary directory and clean-up)

STARTED = []


def start(argv, cwd, pattern):
    """Starts a loopback fake and waits for the line `pattern` (a regex) on its stdout; returns (proc, match)."""
    proc = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    STARTED.append(proc)
    line = proc.stdout.readline()
    match = re.search(pattern, line)
    if not match:
        raise RuntimeError("%s did not start: %s%s" % (argv[0], line, proc.stderr.read()))
    return proc, match


def stop(proc):
    """SIGTERM, then its whole output (stdout and stderr)."""
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=20)
    return out + err


def run(argv, cwd):
    p = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    return p.returncode, p.stdout + p.stderr


def never_settle(selfcal, robot_sim, ur_fake, src, tmp, failures):
    proc, match = start([robot_sim, "--port", "0", "--serial", "HALT-1", "--start-at-plan",
                         "config/trajectories/initial_puma560.yaml", "--never-settle-move", "2"], src,
                        r"listening on 127\.0\.0\.1:(\d+)")
    session = os.path.join(tmp, "s")
    code, out = run([selfcal, "run", "--backend", "network", "--address", "127.0.0.1:" + match.group(1), "--camera",
                     "sim", "--velocity-scaling", "1", "--live-view", "off", "--session", session], src)
    log = stop(proc)
    print(out[-1200:])
    print(log[-400:])
    if code != 4:
        failures.append("exit %d, expected 4 (a halt)" % code)
    if "halted at pose p02: not_settled" not in out or "complete" in out:
        failures.append("the run does not say it halted at p02 for an arm that did not settle:\n" + out[-2000:])
    moves = re.search(r"moves accepted (\d+) of (\d+)", log)
    if not moves or (moves.group(1), moves.group(2)) != ("3", "3"):
        failures.append("the controller received other than 3 MOVEs (p00-p02, none after the halt): " + log[-400:])
    with open(os.path.join(session, "journal.log"), errors="replace") as f:
        journal = f.read()
    if journal.count('"type":"sample"') != 2 and journal.count('"sample_accepted"') != 2:
        samples = len(re.findall(r'"type":"sample[a-z_]*"', journal))
        failures.append("the journal does not keep the 2 samples before the halt (%d sample records)" % samples)
    if "not_settled" not in journal:
        failures.append("the journal does not say why the run halted")


def unconfirmed(selfcal, robot_sim, ur_fake, src, tmp, failures):
    start_deg = "-0.098,-87.56,86.727,-85.646,-90.006,11.888"  # initial_ur5e.yaml's first pose
    proc, match = start([ur_fake, "--rtde-port", "0", "--secondary-port", "0", "--dashboard-port", "0",
                         "--start-deg"] + start_deg.split(","), src,
                        r"listening on 127\.0\.0\.1 rtde (\d+) secondary (\d+) dashboard (\d+)")
    session = os.path.join(tmp, "ur")
    ports = ",".join(match.groups())
    code, out = run([selfcal, "run", "--backend", "ur", "--address", "127.0.0.1", "--ur-ports", ports,
                     "--robot-config", "config/robots/ur5e.yaml", "--camera", "sim", "--velocity-scaling", "1",
                     "--live-view", "off", "--session", session], src)
    log = stop(proc)
    print(out[-1200:])
    print(log[-400:])
    if code != 2:
        failures.append("an unconfirmed real arm: exit %d, expected 2:\n%s" % (code, out[-2000:]))
    if os.path.exists(session):
        failures.append("an unconfirmed run created " + session)
    if "motion commands 0" not in log or "movej" in log:
        failures.append("the controller received a motion command: " + log[-400:])


def main():
    mode, selfcal, robot_sim, ur_fake, src = sys.argv[1:6]
    body = {"never-settle": never_settle, "unconfirmed": unconfirmed}[mode]
    return rehearsal_test.run_mode("network-halt-", lambda tmp, failures: body(selfcal, robot_sim, ur_fake, src, tmp,
                                                                                  failures), STARTED)


if __name__ == "__main__":
    sys.exit(main())
