"""The file kinds of scripts/mutation-campaign: where their valid seeds come from, and the command that
reads a mutant of each.

A kind's prepare(ctx, seed, work, variant) lays out the mutant's work directory (the files the command needs
beside the mutant, copied or linked from the seeds) and returns {"file": the mutant's path relative to work,
"cmd": the command line (run in work), "names": other names the file may be called in a message}; variant (the kind's own count of mutants)
chooses among the commands that read the kind. Every
output goes to work/out, a fresh directory outside any session.
"""
import glob
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys

ROS_SET = "test/data/ros-industrial-dotgrid-10x10"
FRANKA_SET = "test/data/visp-franka-eye-in-hand"
URDF_YAML = {"panda.urdf": "panda_robot.yaml", "puma560.urdf": "puma560_robot.yaml", "ur5e.urdf": "ur5e_robot.yaml",
             "ur5e_named.urdf": "ur5e_named_robot.yaml", "ur5e_meshes.urdf": "ur5e_meshes_robot.yaml"}
TARGET_JOINTS_DEG = [[10, 40, -160, 5, 40, 10], [20, 30, -170, 10, 50, -20], [0, 45, -150, -10, 35, 30]]


def _matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def puma_flange(q_deg, robot_yaml):
    """base_from_flange of a standard-DH config (base_from_link0 and flange identity), for the targets seed."""
    import yaml
    joints = yaml.safe_load(open(robot_yaml))["joints"]
    t = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    for q, jt in zip(q_deg, joints):
        th, al = math.radians(q + jt["theta_offset_deg"]), math.radians(jt["alpha_deg"])
        a, d = jt["a_mm"], jt["d_mm"]
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        t = _matmul(t, [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])
    return t


def targets_text(robot_yaml):
    lines = ["format: selfcal-targets", "version: 1", "robot: puma560", "frame: flange", "targets:"]
    for n, q in enumerate(TARGET_JOINTS_DEG):
        t = puma_flange(q, robot_yaml)
        xyz = ", ".join("%.6f" % t[i][3] for i in range(3))
        rot = ", ".join("[%s]" % ", ".join("%.12f" % t[i][j] for j in range(3)) for i in range(3))
        seed = ", seed_deg: [%s]" % ", ".join(str(v) for v in q) if n != 1 else ""
        lines.append("  - {pose: {xyz_mm: [%s], rotation: [%s]}%s}" % (xyz, rot, seed))
    return "\n".join(lines) + "\n"


def tracker_dir(repo):
    for d in (os.path.join(repo, "..", "shared", "data", "fanuc-lasertracker-kinident"),
              "/work/shared/data/fanuc-lasertracker-kinident"):
        if os.path.isfile(os.path.join(d, "N1N2N3Jval.csv")):
            return os.path.abspath(d)
    return None


class Kind:
    def __init__(self, name, what, fmt, seeds, prepare, quick=False, rules=None):
        self.name, self.what, self.fmt, self._seeds, self._prepare, self.quick = name, what, fmt, seeds, prepare, quick
        self.rules = rules or {}
        self.seed_files = []

    def seeds(self, ctx):
        return sorted(p for p in self._seeds(ctx) if os.path.isfile(p))

    def prepare(self, ctx, seed, work, index):
        os.makedirs(os.path.join(work, "out"), exist_ok=True)
        return self._prepare(ctx, seed, work, index)


def _robot_of_trajectory(path):
    stem = os.path.splitext(os.path.basename(path))[0]
    return stem.split("_")[-1]


def _robot_of_config(path):
    base = os.path.basename(path)
    return {"panda_robot.yaml": "panda", "puma560_robot.yaml": "puma560", "ur5e_robot.yaml": "ur5e",
            "ur5e_named_robot.yaml": "ur5e", "ur5e_meshes_robot.yaml": "ur5e"}.get(base, os.path.splitext(base)[0])


def _link(src, dst):
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    os.symlink(os.path.abspath(src), dst)


def prep_robot_config(ctx, seed, work, index):
    repo = ctx["repo"]
    if seed.endswith("_robot.yaml"):
        for urdf in glob.glob(os.path.join(repo, "test/data/urdf/*.urdf")):
            _link(urdf, os.path.join(work, os.path.basename(urdf)))
    robot = _robot_of_config(seed)
    name = os.path.basename(seed)
    plan = os.path.join(repo, "config/trajectories/initial_%s.yaml" % robot)
    if index % 2:
        cmd = [ctx["bin"], "identifiability", "--robot", name, "--trajectory", plan]
    else:
        cmd = [ctx["bin"], "plan", "--check", plan, "--robot", name]
    return {"file": name, "cmd": cmd}


def prep_urdf(ctx, seed, work, index):
    repo = ctx["repo"]
    for yaml in URDF_YAML.values():
        shutil.copy(os.path.join(repo, "test/data/urdf", yaml), work)
    for urdf in glob.glob(os.path.join(repo, "test/data/urdf/*.urdf")):
        if os.path.basename(urdf) != os.path.basename(seed):
            _link(urdf, os.path.join(work, os.path.basename(urdf)))
    yaml = URDF_YAML[os.path.basename(seed)]
    plan = os.path.join(repo, "config/trajectories/initial_%s.yaml" % _robot_of_config(yaml))
    return {"file": os.path.basename(seed), "cmd": [ctx["bin"], "plan", "--check", plan, "--robot", yaml]}


def prep_trajectory(ctx, seed, work, index):
    robot = os.path.join(ctx["repo"], "config/robots/%s.yaml" % _robot_of_trajectory(seed))
    name = os.path.basename(seed)
    if index % 3 == 2:
        cmd = [ctx["bin"], "identifiability", "--robot", robot, "--trajectory", name]
    else:
        cmd = [ctx["bin"], "plan", "--check", name, "--robot", robot]
    return {"file": name, "cmd": cmd, "robot": robot}


def _observation_context(ctx, seed, work):
    """Copy what an observations file names by a relative path (robot_file, camera_file) beside it."""
    src = os.path.dirname(seed)
    for name in os.listdir(src):
        if name.endswith((".yaml", ".xml", ".urdf")) and name != os.path.basename(seed):
            _link(os.path.join(src, name), os.path.join(work, name))


def prep_observations(ctx, seed, work, index):
    _observation_context(ctx, seed, work)
    name = os.path.basename(seed)
    return {"file": name, "cmd": [ctx["bin"], "calibrate", name, "--out", "out/cal", "--no-html"]}


def _camera_observations(ctx, seed):
    base = os.path.basename(seed)
    if base == "franka_camera.xml":
        return os.path.join(ctx["seeds"], "franka", "franka_obs.yaml")
    return os.path.join(ctx["seeds"], "sim", "observations.yaml")


def prep_camera(ctx, seed, work, index):
    name = os.path.basename(seed)
    obs = _camera_observations(ctx, seed)
    cmd = [ctx["bin"], "calibrate", obs, "--camera-file", name, "--out", "out/cal", "--no-html"]
    if name == "franka_camera.xml":
        cmd += ["--camera-name", "Camera"]
    return {"file": name, "cmd": cmd}


def rehash_input(session, rel):
    """Record the mutated input's size and SHA-256 in session.json, so that the reader of the input, not
    the hash check, sees the mutant (as after a careless edit of both)."""
    path = os.path.join(session, "session.json")
    doc = json.load(open(path))
    data = open(os.path.join(session, rel), "rb").read()
    for entry in doc["inputs"]:
        if entry["name"] == os.path.basename(rel):
            entry["bytes"], entry["sha256"] = len(data), hashlib.sha256(data).hexdigest()
    os.chmod(path, 0o644)
    with open(path, "w") as f:
        json.dump(doc, f, indent=2, sort_keys=True)
        f.write("\n")


def prep_session(ctx, seed, work, index):
    session = os.path.join(ctx["seeds"], "session")
    shutil.copytree(session, os.path.join(work, "session"), symlinks=True)
    rel = os.path.relpath(seed, session)
    after = None
    if rel.startswith("inputs/") and index % 4 != 0:
        after = lambda: rehash_input(os.path.join(work, "session"), rel)  # noqa: E731
    if os.path.basename(seed) == "run.json" or index % 4 == 3:
        cmd = [ctx["bin"], "audit", "session"]
    else:
        cmd = [ctx["bin"], "calibrate", "session", "--out", "out/cal", "--no-html"]
    return {"file": os.path.join("session", rel), "cmd": cmd, "after_write": after,
            "names": ["journal"] if rel == "journal.log" else []}


def prep_pose_files(ctx, seed, work, index):
    pose_dir = os.path.dirname(seed)
    if os.path.basename(pose_dir) == "poses":  # the ROS set: images N.png, poses N.yaml
        for n in range(5):
            _link(os.path.join(pose_dir, "%d.yaml" % n), os.path.join(work, "poses", "%d.yaml" % n))
            _link(os.path.join(ctx["repo"], ROS_SET, "images", "%d.png" % n), os.path.join(work, "images", "%d.png" % n))
        cmd = [ctx["bin"], "detect", "--images", "images", "--poses", "poses", "--camera-fx-px", "542.3",
               "--out", "out/obs.yaml"]
    else:
        for n in range(1, 5):
            _link(os.path.join(pose_dir, "franka_pose_rPe_%d.yaml" % n), os.path.join(work, "poses", "franka_pose_rPe_%d.yaml" % n))
            _link(os.path.join(pose_dir, "franka_image-%d.png" % n), os.path.join(work, "images", "franka_image-%d.png" % n))
        cmd = [ctx["bin"], "detect", "--images", "images", "--poses", "poses", "--detector", "chessboard", "--grid",
               "6x9", "--camera-fx-px", "607.6", "--camera-cx-px", "323.46", "--camera-cy-px", "243.26",
               "--out", "out/obs.yaml"]
    return {"file": os.path.join("poses", os.path.basename(seed)), "cmd": cmd}


def prep_model(ctx, seed, work, index):
    targets = os.path.join(ctx["seeds"], "targets.yaml")
    robot = os.path.join(ctx["repo"], "config/robots/puma560.yaml")
    cmd = [ctx["bin"], "compensate", "calibrated_model.yaml", "--targets", targets, "--out", "out/joints.yaml"]
    return {"file": "calibrated_model.yaml", "cmd": cmd + (["--robot", robot] if index % 2 else [])}


def prep_targets(ctx, seed, work, index):
    model = os.path.join(ctx["seeds"], "sim", "calibrated_model.yaml")
    robot = os.path.join(ctx["repo"], "config/robots/puma560.yaml")
    cmd = [ctx["bin"], "compensate", model, "--targets", "targets.yaml", "--out", "out/joints.yaml"]
    return {"file": "targets.yaml", "cmd": cmd + (["--robot", robot] if index % 2 else [])}


def prep_report(ctx, seed, work, index):
    name = os.path.basename(seed)
    return {"file": name, "cmd": [ctx["bin"], "report", name, "--out", "out/report.html"]}


def prep_tracker(ctx, seed, work, index):
    src = os.path.dirname(seed)
    for name in os.listdir(src):
        if name != os.path.basename(seed):
            _link(os.path.join(src, name), os.path.join(work, "tracker", name))
    name = os.path.basename(seed)
    return {"file": os.path.join("tracker", name),
            "cmd": [ctx["bin"], "identify-tracker", "--data", "tracker", "--file", name, "--holdout-every", "3",
                    "--out", "out/tracker"]}


def _seeds_in(*parts):
    return lambda c: sorted(glob.glob(os.path.join(c["seeds"], *parts)))


def all_kinds():
    repo_glob = lambda pattern: (lambda c: sorted(glob.glob(os.path.join(c["repo"], pattern))))  # noqa: E731
    session = lambda *names: (lambda c: [os.path.join(c["seeds"], "session", n) for n in names])  # noqa: E731
    return [
        Kind("robot_config", "robot config YAML (config/robots, test/data/urdf/*_robot.yaml): plan --check, identifiability",
             "yaml", lambda c: repo_glob("config/robots/*.yaml")(c) + repo_glob("test/data/urdf/*_robot.yaml")(c),
             prep_robot_config, quick=True),
        Kind("urdf", "URDF named by a robot config: plan --check", "xml", repo_glob("test/data/urdf/*.urdf"), prep_urdf,
             quick=True),
        Kind("trajectory", "trajectory and plan files (config/trajectories): plan --check, identifiability", "yaml",
             repo_glob("config/trajectories/*.yaml"), prep_trajectory, quick=True),
        Kind("observations", "observations YAML (simulate --points, detect of the ROS and ViSP sets): calibrate", "yaml",
             lambda c: _seeds_in("sim", "observations.yaml")(c) + _seeds_in("ros", "ros_obs.yaml")(c) +
             _seeds_in("franka", "franka_obs.yaml")(c), prep_observations, quick=True),
        Kind("camera_opencv", "OpenCV FileStorage camera file: calibrate --camera-file", "opencv",
             _seeds_in("cam_opencv.yaml"), prep_camera, quick=True),
        Kind("camera_visp", "ViSP camera XML: calibrate --camera-file", "xml",
             lambda c: _seeds_in("cam_visp.xml")(c) + [os.path.join(c["repo"], FRANKA_SET, "franka_camera.xml")]
             if os.path.isfile(os.path.join(c["seeds"], "franka", "franka_obs.yaml")) else _seeds_in("cam_visp.xml")(c),
             prep_camera, quick=True),
        Kind("session_json", "a session's session.json (manifest): calibrate, audit", "json", session("session.json"),
             prep_session),
        Kind("setup_json", "a session's setup.json: calibrate, audit", "json", session("inputs/setup.json", "setup.json"),
             prep_session),
        Kind("run_json", "a session's run.json: audit", "json", session("run.json", "inputs/run.json"), prep_session),
        Kind("journal", "a session's journal.log: calibrate, audit", "journal", session("journal.log"), prep_session),
        Kind("session_inputs", "a session's inputs/robot.yaml: calibrate, audit (inputs/plan.yaml is read by neither: "
             "they take the plan from the journal)", "yaml", session("inputs/robot.yaml"), prep_session),
        Kind("ros_pose", "ROS per-image pose files (ROS-Industrial set): detect", "yaml",
             lambda c: [os.path.join(c["repo"], ROS_SET, "poses", "%d.yaml" % n) for n in range(5)], prep_pose_files),
        Kind("visp_pose", "ViSP vpPoseVector per-image pose files (Franka set): detect", "opencv",
             lambda c: [os.path.join(c["repo"], FRANKA_SET, "franka_pose_rPe_%d.yaml" % n) for n in range(1, 5)],
             prep_pose_files),
        Kind("calibrated_model", "calibrated_model.yaml: compensate", "yaml", _seeds_in("sim", "calibrated_model.yaml"),
             prep_model, quick=True),
        Kind("targets", "targets file of compensate", "yaml", _seeds_in("targets.yaml"), prep_targets, quick=True),
        Kind("report_json", "report.json of calibrate/simulate: report", "json",
             lambda c: _seeds_in("sim", "report.json")(c) + _seeds_in("session-cal", "report.json")(c),
             prep_report, quick=True),
        Kind("study_json", "study JSON: report", "json", _seeds_in("study.json"), prep_report),
        Kind("tracker", "laser-tracker data (Fanuc N1N2N3Jval.csv): identify-tracker", "csv",
             _seeds_in("tracker", "N1N2N3Jval.csv"), prep_tracker),
    ]


def _run(ctx, cmd, what):
    print("seed: %s" % what, file=sys.stderr)
    res = subprocess.run(cmd, cwd=ctx["repo"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if res.returncode != 0:
        print("  exit %d: %s" % (res.returncode, res.stderr.strip()[-500:]), file=sys.stderr)
    return res.returncode


def prepare_seeds(ctx, chosen):
    """Make the generated seeds in ctx["seeds"] (once: kept and reused)."""
    names = {k.name for k in chosen}
    s, b, repo = ctx["seeds"], ctx["bin"], ctx["repo"]
    os.makedirs(s, exist_ok=True)
    if not os.path.isfile(os.path.join(s, "sim", "observations.yaml")):
        _run(ctx, [b, "simulate", "--points", "--robot", "config/robots/puma560.yaml", "--trajectory",
                   "config/trajectories/planned_d-optimal_puma560.yaml", "--out", os.path.join(s, "sim"), "--no-html"],
             "simulate --points")
    if not os.path.isfile(os.path.join(s, "cam_opencv.yaml")):
        _run(ctx, [b, "calibrate", os.path.join(s, "sim", "observations.yaml"), "--out", os.path.join(s, "sim-cal"),
                   "--no-html", "--write-camera-opencv", os.path.join(s, "cam_opencv.yaml"),
                   "--write-camera-visp", os.path.join(s, "cam_visp.xml")], "camera files")
    if not os.path.isfile(os.path.join(s, "targets.yaml")):
        with open(os.path.join(s, "targets.yaml"), "w") as f:
            f.write(targets_text(os.path.join(repo, "config/robots/puma560.yaml")))
    if "observations" in names and not os.path.isfile(os.path.join(s, "ros", "ros_obs.yaml")) and not ctx.get("quick"):
        os.makedirs(os.path.join(s, "ros"), exist_ok=True)
        _run(ctx, [b, "detect", "--images", ROS_SET + "/images", "--poses", ROS_SET + "/poses", "--camera-fx-px", "542.3",
                   "--out", os.path.join(s, "ros", "ros_obs.yaml")], "detect (ROS set)")
    if ({"observations", "camera_visp"} & names) and not os.path.isfile(os.path.join(s, "franka", "franka_obs.yaml")):
        os.makedirs(os.path.join(s, "franka"), exist_ok=True)
        _run(ctx, [b, "detect", "--images", FRANKA_SET + "/franka_image-*.png", "--poses", FRANKA_SET + "/franka_pose_rPe_*.yaml",
                   "--detector", "chessboard", "--grid", "6x9", "--camera-fx-px", "607.6", "--camera-cx-px", "323.46",
                   "--camera-cy-px", "243.26", "--out", os.path.join(s, "franka", "franka_obs.yaml")], "detect (Franka set)")
    if any(k.name.startswith(("session", "setup", "run_", "journal")) for k in chosen) and \
            not os.path.isfile(os.path.join(s, "session", "session.json")):
        _run(ctx, [b, "run", "--session", os.path.join(s, "session"), "--seed", "3"], "run --session --seed 3")
    if "report_json" in names and not os.path.isfile(os.path.join(s, "session-cal", "report.json")) and \
            os.path.isfile(os.path.join(s, "session", "session.json")):
        _run(ctx, [b, "calibrate", os.path.join(s, "session"), "--out", os.path.join(s, "session-cal"), "--no-html"],
             "calibrate the session")
    if "study_json" in names and not os.path.isfile(os.path.join(s, "study.json")):
        _run(ctx, [b, "study", "--runs", "2", "--no-opencv", "--out", os.path.join(s, "study.json")], "study --runs 2")
    tracker = tracker_dir(repo)
    if "tracker" in names and tracker and not os.path.isdir(os.path.join(s, "tracker")):
        shutil.copytree(tracker, os.path.join(s, "tracker"))
        for name in os.listdir(os.path.join(s, "tracker")):
            os.chmod(os.path.join(s, "tracker", name), 0o644)
