#!/usr/bin/python3
"""A network session rehearsed without hardware (README, "Rehearse a network session"), on loopback.

  rehearsal_test.py dry-run|session SELFCAL SELFCAL_ROBOT_SIM SOURCE_DIR

dry-run: with selfcal-robot-sim on a free port, `run --backend network --dry-run` needs no camera: with
  `--camera v4l2 --device` naming no device it prints the preview and exits 0 (it used to halt opening the
  camera), and with `--camera sim` (the simulated camera following the network robot) likewise; nothing is
  created and no MOVE reaches the server.
session: selfcal-robot-sim (started at the default plan's first pose) plus `run --backend network --camera
  sim` records the whole default plan (25 poses), `audit` finds its identities right against the cell
  rebuilt from its inputs (the world that rendered it), `calibrate` accepts it, and its figures equal those of
  the same plan and seed on `--backend sim` within the statistics: every free parameter and f_x within 4
  combined standard deviations (sqrt(s1^2 + s2^2): the two sessions' images carry different pixel noise,
  their frames being numbered differently), the same free set, and both check-distance RMS below 0.5 mm.
"""
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile

PLAN = "config/trajectories/initial_puma560.yaml"


STARTED = []  # every server a test started: stopped at the end whatever happened


class Server:
    """selfcal-robot-sim on 127.0.0.1, any free port (it prints the one it got)."""

    def __init__(self, binary, cwd, extra):
        self.proc = subprocess.Popen([binary, "--port", "0", "--serial", "REHEARSAL-1"] + extra, cwd=cwd,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        STARTED.append(self.proc)
        line = self.proc.stdout.readline()
        if not line.startswith("listening on 127.0.0.1:"):
            raise RuntimeError("selfcal-robot-sim did not start: " + line + self.proc.stderr.read())
        self.port = int(line.strip().rsplit(":", 1)[1])

    def stop(self):
        """Stops it (SIGTERM) and returns its stderr (its last line counts the moves)."""
        self.proc.send_signal(signal.SIGTERM)
        _, err = self.proc.communicate(timeout=20)
        return err


def run(binary, args, cwd):
    p = subprocess.run([binary] + args, cwd=cwd, capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout + p.stderr


def dry_run(selfcal, robot_sim, src, tmp, failures):
    server = Server(robot_sim, src, ["--start-at-plan", PLAN])
    setup = os.path.join(tmp, "setup.json")
    # A setup.json for the v4l2 case: a simulated session's (any valid one would do).
    code, out = run(selfcal, ["run", "--backend", "sim", "--camera", "sim", "--live-view", "off",
                              "--session", os.path.join(tmp, "sim")], src)
    if code == 0:
        shutil.copy(os.path.join(tmp, "sim", "inputs", "setup.json"), setup)
    cases = {
        "v4l2 without a device": ["--camera", "v4l2", "--device", os.path.join(tmp, "no-such-video"), "--setup", setup],
        "sim camera following the network robot": ["--camera", "sim"],
    }
    for name, camera in cases.items():
        if "--setup" in camera and not os.path.exists(setup):
            failures.append(name + ": no setup.json to run with (simulate: " + out[-500:] + ")")
            continue
        session = os.path.join(tmp, "dry-" + name.split()[0])
        code, out = run(selfcal, ["run", "--backend", "network", "--address", "127.0.0.1:%d" % server.port,
                                  "--velocity-scaling", "1", "--dry-run", "--live-view", "off",
                                  "--session", session] + camera, src)
        if code != 0:
            failures.append("%s: dry run exit %d, expected 0:\n%s" % (name, code, out))
        if "dry run: nothing moved" not in out or "25 moves," not in out:
            failures.append(name + ": no preview of the 25 poses:\n" + out)
        if os.path.exists(session):
            failures.append(name + ": a dry run created " + session)
    log = server.stop()
    if "moves accepted 0 of 0" not in log:
        failures.append("the dry runs sent a MOVE: " + log)


def report_of(selfcal, src, session, out, failures):
    code, text = run(selfcal, ["calibrate", session, "--out", out, "--no-html"], src)
    if code != 0:
        failures.append("calibrate %s: exit %d\n%s" % (session, code, text[-3000:]))
        return None
    with open(os.path.join(out, "report.json")) as f:
        return json.load(f)


def whole_session(selfcal, robot_sim, src, tmp, failures):
    server = Server(robot_sim, src, ["--start-at-plan", PLAN])
    network = os.path.join(tmp, "network")
    code, out = run(selfcal, ["run", "--backend", "network", "--address", "127.0.0.1:%d" % server.port,
                              "--camera", "sim", "--velocity-scaling", "1", "--seed", "1", "--live-view", "off",
                              "--session", network], src)
    log = server.stop()
    print(out[-1500:])
    print(log)
    if code != 0 or "run: completed: session complete: 25 samples accepted" not in out:
        failures.append("network run with --camera sim: exit %d\n%s" % (code, out[-3000:]))
        return
    if "camera sim: the simulated cell of seed 1" not in out:
        failures.append("the run does not say which world rendered its images:\n" + out[:2000])
    with open(os.path.join(network, "inputs", "run.json")) as f:
        recorded = json.load(f)
    if (recorded["robot"], recorded["camera"], recorded["seed"]) != ("network", "sim", 1):
        failures.append("run.json does not record the network robot, the simulated camera and seed 1: %s" % recorded)
    # Which world rendered the images: `audit` rebuilds the cell from the session's inputs (robot.yaml,
    # plan, run.json's seed; setup.json must match) and scores every recorded identity against its truth.
    audit_json = os.path.join(tmp, "audit.json")
    code, out = run(selfcal, ["audit", network, "--json", audit_json], src)
    if code != 0:
        failures.append("audit of the network session: exit %d\n%s" % (code, out[-2000:]))
    else:
        with open(audit_json) as f:
            audit = json.load(f)["identities"]
        print("audit: %d samples, %d wrong identities, named %.0f of %.0f dots in view per sample, worst %.3f px" %
              (audit["samples_accepted"], audit["wrong_total"], audit["named_per_sample"]["mean"],
               audit["in_view_per_sample"]["mean"], audit["max_right_error_px"]))
        if audit["wrong_total"] != 0 or audit["samples_accepted"] != 25 or not audit["max_right_error_px"] < 0.5:
            failures.append("audit of the network session: %s" % json.dumps(audit)[:2000])
    with open(os.path.join(network, "journal.log"), errors="replace") as f:
        journal = f.read()
    for recorded in ('"robot_serial":"REHEARSAL-1"', '"camera":"simulated camera: ', "real time"):
        if recorded not in journal:
            failures.append("the network session's journal does not record " + recorded)
    faults = journal_faults(network)
    print("faults recorded: %s" % faults)
    if faults:  # a fault-free cell records none
        failures.append("a fault-free network run recorded faults: %s" % faults)
    compare_with_simulated(selfcal, src, tmp, network, "network", failures)


def journal_records(session):
    """The journal's records, in order."""
    with open(os.path.join(session, "journal.log"), errors="replace") as f:
        for line in f:
            parts = line.split(" ", 3)
            if len(parts) == 4 and parts[0] == "J1":
                yield json.loads(parts[3])


def journal_faults(session):
    """The journal's fault records' kinds, with their counts."""
    kinds = {}
    for record in journal_records(session):
        if record.get("type") == "fault":
            kinds[record["kind"]] = kinds.get(record["kind"], 0) + 1
    return kinds


def compare_with_simulated(selfcal, src, tmp, session, label, failures):
    """Calibrates `session` (a seed-1 run of the default plan with --camera sim on robot backend `label`) and
    the same plan and seed on `--backend sim`: both accepted, 25 samples, the same free set, every free
    parameter and f_x within 4 combined standard deviations, both check-distance RMS below 0.5 mm. Returns
    `session`'s report (None when a step failed)."""
    simulated = os.path.join(tmp, "simulated")
    code, out = run(selfcal, ["run", "--backend", "sim", "--camera", "sim", "--seed", "1", "--live-view", "off",
                              "--session", simulated], src)
    if code != 0:
        failures.append("simulated run: exit %d\n%s" % (code, out[-3000:]))
        return None
    a = report_of(selfcal, src, session, os.path.join(tmp, "cal-" + label), failures)
    b = report_of(selfcal, src, simulated, os.path.join(tmp, "cal-simulated"), failures)
    if a is None or b is None:
        return None
    if not (a["accepted"] and b["accepted"]):
        failures.append("verdicts: %s %s, simulated %s" % (label, a["verdict"], b["verdict"]))
    if a["session"]["samples_accepted"] != 25:
        failures.append("%s session: %d samples accepted, not 25" % (label, a["session"]["samples_accepted"]))
    pa = {p["name"]: p for p in a["methods"]["bundle"]["parameters"]}
    pb = {p["name"]: p for p in b["methods"]["bundle"]["parameters"]}
    free_a = sorted(n for n, p in pa.items() if p["free"])
    if free_a != sorted(n for n, p in pb.items() if p["free"]):
        failures.append("different free parameters")
    worst = (0.0, "")
    for name in free_a:
        unit = "m" if "value_m" in pa[name] else "rad"
        d = pa[name]["value_" + unit] - pb[name]["value_" + unit]
        s = math.hypot(pa[name]["stddev_" + unit], pb[name]["stddev_" + unit])
        worst = max(worst, (abs(d) / s, name))
    fa, fb = a["methods"]["bundle"], b["methods"]["bundle"]
    worst = max(worst, (abs(fa["fx_px"] - fb["fx_px"]) / math.hypot(fa["fx_stddev_px"], fb["fx_stddev_px"]), "fx"))
    print("largest difference %s - simulated: %.2f combined sigma (%s)" % ((label,) + worst))
    if worst[0] > 4:
        failures.append("%s differs by %.2f combined standard deviations between the two sessions" % (worst[1], worst[0]))
    for name, r in ((label, a), ("simulated", b)):
        rms = r["verification"]["calibrated_model"]["rms_error_m"]
        print("%s: check distances %.3f mm RMS, held-out %.4f px RMS" %
              (name, 1000 * rms, r["heldout_reprojection"]["calibrated_model"]["overall"]["rms_px"]))
        if not rms < 5e-4:
            failures.append("%s: check distances at %.3f mm RMS" % (name, 1000 * rms))
    return a


def run_mode(prefix, body, started):
    """Runs body(tmp, failures) in a fresh temporary directory, kills whatever of `started` still runs, prints
    the failures; the exit code (1 on any failure). Shared by the loopback tests of this directory."""
    failures = []
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        try:
            body(tmp, failures)
        except AssertionError as e:
            failures.append(str(e))
        finally:
            for proc in started:
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


def main():
    mode, selfcal, robot_sim, src = sys.argv[1:5]
    body = {"dry-run": dry_run, "session": whole_session}[mode]
    return run_mode("rehearsal-", lambda tmp, failures: body(selfcal, robot_sim, src, tmp, failures), STARTED)


if __name__ == "__main__":
    sys.exit(main())
