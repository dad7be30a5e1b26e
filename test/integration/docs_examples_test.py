#!/usr/bin/python3
"""The documentation is true to the program (issue: formats true to what the program writes).

  docs_examples_test.py SELFCAL_BINARY SOURCE_DIR WORK_DIR

1. Every fenced file example (yaml, json, xml) in docs/*.md is classified below and read by the program:
   complete examples by the command that takes such a file (it must not refuse the file's format: its
   readers refuse unknown keys), and the keys of the examples no command can read alone (abridged with
   "# ...", a block of a file, a manifest) must be keys the program writes in a file of that kind, made
   here by running the program. An example nobody classified fails the test.
2. Every key the program writes at the top level of those files is named in its document.
3. Every `selfcal` command line in docs/*.md and README.md (fenced sh blocks and inline code) names an
   existing command, and each of its --options appears in that command's --help.
4. docs/troubleshooting.md has an entry for every exit code (app/exit_codes.h) and every outcome word the
   program prints (calibration verdicts, run outcomes, acceptance checks, and the skip, fault and halt
   reasons session-format.md lists), and every message it quotes in its tables is the program's wording.

Uses Debian's python3-yaml. Prints every problem; exits 1 when there is one.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys

import yaml

SELFCAL, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
problems = []


def problem(text):
    problems.append(text)
    print("FAIL:", text)


def run(args, cwd=None):
    return subprocess.run([SELFCAL] + args, cwd=cwd or WORK, capture_output=True, text=True, timeout=600)


def fenced_blocks(path):
    """(language, text, line) of every fenced block of a markdown file."""
    blocks, lang, start, lines = [], None, 0, []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, start=1):
            fence = re.match(r"^```(\w*)\s*$", line)
            if fence and lang is None:
                lang, start, lines = fence.group(1), number, []
            elif line.startswith("```") and lang is not None:
                blocks.append((lang, "".join(lines), start))
                lang = None
            elif lang is not None:
                lines.append(line)
    return blocks


# ---- the program's own files of every documented kind ----------------------------------------------------
def make_real_files():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    steps = [
        ["plan", "--out", "plan.yaml"],
        ["simulate", "--points", "--seed", "3", "--out", "sim"],
        ["run", "--session", "session", "--seed", "1", "--plan",
         os.path.join(SRC, "config", "trajectories", "initial_puma560.yaml")],
        ["calibrate", "sim/observations.yaml", "--out", "cal", "--write-camera-opencv", "cal/camera.yaml",
         "--write-camera-visp", "cal/camera.xml"],
        ["simulate", "--points", "--no-html", "--robot", os.path.join(SRC, "config", "robots", "ur5e.yaml"),
         "--trajectory", os.path.join(SRC, "config", "trajectories", "initial_ur5e.yaml"), "--out", "sim-ur5e"],
    ]
    # detect --skip-failed on three ROS images, one replaced by a blank one: its skipped list.
    ros = os.path.join(SRC, "test", "data", "ros-industrial-dotgrid-10x10")
    for sub in ("images", "poses"):
        os.makedirs(os.path.join(WORK, "detect", sub))
    for i in range(3):
        shutil.copy(os.path.join(ros, "poses", f"{i}.yaml"), os.path.join(WORK, "detect", "poses"))
        if i != 1:
            shutil.copy(os.path.join(ros, "images", f"{i}.png"), os.path.join(WORK, "detect", "images"))
    with open(os.path.join(WORK, "detect", "images", "1.pgm"), "wb") as f:
        f.write(b"P5\n640 480\n255\n" + bytes([200]) * (640 * 480))
    steps.append(["detect", "--images", "detect/images", "--poses", "detect/poses", "--camera-fx-px", "542.3",
                  "--out", "detect/obs.yaml", "--skip-failed"])
    for step in steps:
        result = run(step)
        if result.returncode != 0:
            problem(f"selfcal {' '.join(step)} exited {result.returncode}: {result.stderr[-2000:]}")
    return {
        "skipped_images": os.path.join(WORK, "detect", "obs.skipped.yaml"),
        "plan": os.path.join(WORK, "plan.yaml"),
        "observations": os.path.join(WORK, "sim", "observations.yaml"),
        "calibrated_model": os.path.join(WORK, "cal", "calibrated_model.yaml"),
        "robot": os.path.join(SRC, "config", "robots", "puma560.yaml"),
        "session_json": os.path.join(WORK, "session", "session.json"),
        "setup_json": os.path.join(WORK, "session", "inputs", "setup.json"),
        "static_transform": os.path.join(WORK, "cal", "camera_static_transform.yaml"),
        "camera_info": os.path.join(WORK, "cal", "camera_info.yaml"),
        "ur_kinematics": os.path.join(WORK, "sim-ur5e", "ur_calibrated_kinematics.yaml"),
    }


def load_any(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    return json.loads(text) if path.endswith(".json") else yaml.safe_load(text)


def key_paths(node, prefix=""):
    """Every key path of a parsed document; a list contributes the keys of its elements as `key[]`."""
    paths = set()
    if isinstance(node, dict):
        for k, v in node.items():
            p = f"{prefix}.{k}" if prefix else str(k)
            paths.add(p)
            paths |= key_paths(v, p)
    elif isinstance(node, list):
        for v in node:
            paths |= key_paths(v, prefix + "[]")
    return paths


# ---- classification of the documented examples ----------------------------------------------------------
def kind_of(lang, text):
    """(kind, how it is read) of one fenced example; None when it is not a file example."""
    body = "\n".join(l for l in text.splitlines() if l.strip() and not l.lstrip().startswith("#"))
    if lang not in ("yaml", "json", "xml"):
        return None
    if lang == "xml":
        return ("visp_camera", "camera")
    if body.startswith("%YAML:1.0"):
        return ("opencv_camera", "camera")
    if lang == "json" and '"selfcal-session"' in text:
        return ("session_json", "keys")
    if "format: selfcal-observations" in text:
        return ("observations", "observations")
    if "format: selfcal-trajectory" in text:
        return ("plan" if "num_identification_poses" in text else "trajectory", "trajectory")
    if body.startswith("planned_for:"):
        return ("plan", "keys")
    if "format: selfcal-calibrated-model" in text:
        return ("calibrated_model", "keys")
    if "dh_convention:" in text:
        return ("robot", "keys")
    if "urdf_file:" in text:
        return ("urdf_robot", "urdf_robot")
    if "format: selfcal-skipped-images" in text:
        return ("skipped_images", "keys")
    if "format: selfcal-targets" in text:
        return ("targets", "targets")
    if body.startswith("header:") and "child_frame_id:" in text:
        return ("static_transform", "keys")
    if body.startswith("image_width:") and "distortion_model:" in text:
        return ("camera_info", "keys")
    if body.startswith("kinematics:") and "hash:" in text:
        return ("ur_kinematics", "keys")
    return ("unclassified", None)


# Keys an abridged example shows that the program reads but writes only when a user gave them.
OPTIONAL_UNWRITTEN = {
    "plan": {"planned_for.scene_extent_mm"},  # optional: the points every image must contain (default: the dots)
}


def abridged(text):
    return re.search(r"#\s*\.\.\.|\[\.\.\.\]", text) is not None


def parse_example(text):
    return yaml.safe_load(re.sub(r"\[\.\.\.\]", "[0]", text))


def check_reads(kind, how, text, where, real):
    path = os.path.join(WORK, "example-" + re.sub(r"\W", "_", where))
    if how == "observations":
        text = text.replace("../config/robots/", os.path.join(SRC, "config", "robots") + "/")
        with open(path + ".yaml", "w", encoding="utf-8") as f:
            f.write(text)
        result = run(["calibrate", path + ".yaml", "--out", path + "-out"])
        # A two-pose example cannot calibrate (exit 3); its format must not be refused (exit 2).
        if result.returncode == 2:
            problem(f"{where}: selfcal calibrate refuses the documented example: {result.stderr[-1500:]}")
    elif how == "trajectory" and not abridged(text):
        with open(path + ".yaml", "w", encoding="utf-8") as f:
            f.write(text)
        # A documented trajectory is one the plan check passes on the shipped robot it names.
        result = run(["plan", "--check", path + ".yaml", "--robot", real["robot"]])
        if result.returncode != 0:
            problem(f"{where}: selfcal plan --check refuses the documented example (exit {result.returncode}): "
                    f"{(result.stdout + result.stderr)[-1500:]}")
    elif how == "urdf_robot":
        # A robot config naming a URDF (docs/urdf.md): the test URDF of its urdf_file beside it, simulated on
        # the trajectory of that robot; its format must not be refused (exit 2).
        urdf = re.search(r"^urdf_file:\s*(\S+)", text, re.M).group(1)
        os.makedirs(path, exist_ok=True)
        shutil.copy(os.path.join(SRC, "test", "data", "urdf", os.path.basename(urdf)), os.path.join(path, urdf))
        with open(os.path.join(path, "robot.yaml"), "w", encoding="utf-8") as f:
            f.write(text)
        robot = os.path.basename(urdf).split(".")[0]
        result = run(["simulate", "--points", "--no-html", "--robot", os.path.join(path, "robot.yaml"), "--trajectory",
                      os.path.join(SRC, "config", "trajectories", f"initial_{robot}.yaml"), "--out", path + "-out"])
        if result.returncode == 2:
            problem(f"{where}: selfcal simulate --robot refuses the documented example: {result.stderr[-1500:]}")
    elif how == "targets":
        with open(path + ".yaml", "w", encoding="utf-8") as f:
            f.write(text)
        # compensate on the simulated calibration: a target may be out of reach (exit 5), never refused (2).
        result = run(["compensate", real["calibrated_model"], "--targets", path + ".yaml", "--out", path + "-joints.yaml"])
        if result.returncode == 2:
            problem(f"{where}: selfcal compensate refuses the documented example: {result.stderr[-1500:]}")
    elif how == "camera":
        suffix = ".xml" if kind == "visp_camera" else ".yaml"
        with open(path + suffix, "w", encoding="utf-8") as f:
            f.write(text)
        result = run(["calibrate", real["observations"], "--camera-file", path + suffix, "--out", path + "-out"])
        if result.returncode == 2:
            problem(f"{where}: selfcal calibrate --camera-file refuses the documented example: "
                    f"{result.stderr[-1500:]}")


def check_examples(real):
    written = {kind: key_paths(load_any(path)) for kind, path in real.items() if os.path.exists(path)}
    written["trajectory"] = written.get("plan", set())
    for doc in sorted(glob.glob(os.path.join(SRC, "docs", "*.md"))):
        for lang, text, line in fenced_blocks(doc):
            classified = kind_of(lang, text)
            if classified is None:
                continue
            where = f"{os.path.relpath(doc, SRC)}:{line}"
            kind, how = classified
            if how is None:
                problem(f"{where}: a {lang} example that no test reads (classify it in docs_examples_test.py)")
                continue
            check_reads(kind, how, text, where, real)
            print(f"{where}: a {kind} example, {'read by selfcal' if how != 'keys' else 'keys checked'}")
            if kind in ("opencv_camera", "visp_camera"):
                continue  # other programs' formats: read above, written by selfcal in camera_files tests
            if how != "keys":
                continue  # read whole by the program above, whose readers refuse unknown keys
            example = json.loads(text) if lang == "json" else parse_example(text)
            paths = key_paths(example) - OPTIONAL_UNWRITTEN.get(kind, set())
            missing = sorted(p for p in paths if p not in written.get(kind, set()))
            if missing:
                problem(f"{where}: keys the program does not write in a {kind} file: {', '.join(missing)}")


def check_written_keys_documented(real):
    docs = {"plan": "trajectory-format.md", "observations": "observations-format.md",
            "calibrated_model": "calibrated-model-format.md", "session_json": "session-format.md",
            "setup_json": "session-format.md", "skipped_images": "detect.md"}
    for kind, doc in docs.items():
        if not os.path.exists(real[kind]):
            continue
        with open(os.path.join(SRC, "docs", doc), encoding="utf-8") as f:
            text = f.read()
        node = load_any(real[kind])
        for key in node if isinstance(node, dict) else []:
            if f"`{key}`" not in text and f"{key}:" not in text and f'"{key}"' not in text:
                problem(f"docs/{doc}: does not name `{key}`, which selfcal writes in {os.path.basename(real[kind])}")


# ---- command lines ------------------------------------------------------------------------------------
def command_lines():
    """(where, tokens after `selfcal`) of every selfcal command line in docs/*.md and README.md."""
    found = []
    files = sorted(glob.glob(os.path.join(SRC, "docs", "*.md"))) + [os.path.join(SRC, "README.md")]
    for path in files:
        rel = os.path.relpath(path, SRC)
        for lang, text, line in fenced_blocks(path):
            if lang not in ("sh", "bash", ""):
                continue
            joined = re.sub(r"\\\n\s*", " ", text)
            for k, l in enumerate(joined.splitlines()):
                m = re.match(r"^\s*(?:\$\s+)?(?:\S*/)?selfcal\s+([a-z].*)$", l)
                if m:
                    found.append((f"{rel}:{line}", m.group(1).split("#")[0].split()))
        with open(path, encoding="utf-8") as f:
            for number, l in enumerate(f, start=1):
                for span in re.findall(r"`selfcal ([a-z][^`]*)`", l):
                    found.append((f"{rel}:{number}", span.split()))
    return found


def subcommands(args):
    """The subcommand names a --help lists under "Subcommands:"."""
    text = run(args + ["--help"]).stdout
    listed = text.split("Subcommands:", 1)[1] if "Subcommands:" in text else ""
    return {m.group(1) for m in re.finditer(r"^  ([a-z][a-z-]*)\s", listed, re.M)}


def check_command_lines():
    helps = {}
    commands = subcommands([])
    commands |= {"session " + c for c in subcommands(["session"])}
    lines = command_lines()
    print(f"{len(lines)} selfcal command lines in the docs")
    for where, tokens in lines:
        words = [t for t in tokens if re.fullmatch(r"[a-z][a-z-]*", t)]
        if not words:
            continue
        command = words[:2] if words[0] == "session" and len(words) > 1 else words[:1]
        key = " ".join(command)
        if key not in commands:
            problem(f"{where}: `selfcal {key}` is not a command")
            continue
        if key not in helps:
            result = run(command + ["--help"])
            helps[key] = result.stdout if result.returncode == 0 else None
        if helps[key] is None:
            problem(f"{where}: `selfcal {key}` is not a command")
            continue
        for t in tokens:
            option = re.match(r"^(--[a-z][a-z0-9-]*)", t)
            if option and not re.search(re.escape(option.group(1)) + r"(?![a-z0-9-])", helps[key]):
                problem(f"{where}: `selfcal {key}` has no option {option.group(1)}")


# ---- troubleshooting.md: keyed by every exit code and outcome, in the program's own words -------------------
def program_sources():
    text = ""
    for path in glob.glob(os.path.join(SRC, "app", "*.cc")) + glob.glob(os.path.join(SRC, "modules", "*", "*.cc")):
        if not path.endswith("_test.cc"):
            with open(path, encoding="utf-8") as f:
                text += f.read()
    # String literals split over lines ("a " "b") read as one.
    return re.sub(r'"\s*\n\s*"', "", text)


def check_troubleshooting():
    with open(os.path.join(SRC, "docs", "troubleshooting.md"), encoding="utf-8") as f:
        guide = f.read()
    with open(os.path.join(SRC, "app", "exit_codes.h"), encoding="utf-8") as f:
        codes = f.read()
    sources = program_sources()
    names = re.findall(r'case ExitCode::k\w+: return "(\w+)";', codes)
    values = re.findall(r"^\s*k\w+ = (\d+),", codes, re.M)
    outcomes = set(names)
    for function in ("VerdictName", "RunOutcomeName"):
        body = re.search(function + r"\([^)]*\) \{(.*?)\n\}", sources, re.S)
        outcomes |= set(re.findall(r'return "(\w+)";', body.group(1))) if body else set()
    outcomes |= set(re.findall(r'AcceptanceCheck check\{"(\w+)"', sources))
    with open(os.path.join(SRC, "docs", "session-format.md"), encoding="utf-8") as f:
        session_doc = f.read()
    for heading in ("Final skip reasons:", "Fault kinds:", "Halt reasons:"):
        listed = re.search(re.escape(heading) + r"(.*?)(?:\.\s|\n\n)", session_doc, re.S)
        outcomes |= set(re.findall(r"`([a-z_<>]+)`", listed.group(1))) if listed else set()
    for value in values:
        if not re.search(rf"^## Exit {value}\b|^\| {value} \|", guide, re.M):
            problem(f"docs/troubleshooting.md: exit code {value} has no entry")
    for outcome in sorted(outcomes - {"unknown", "not_run"}):
        if f"`{outcome}`" not in guide:
            problem(f"docs/troubleshooting.md: the outcome `{outcome}` the program prints has no entry")
    # Every quoted phrase of the guide's tables is the program's own wording.
    for line in guide.splitlines():
        if not line.startswith("| "):
            continue
        for phrase in re.findall(r"`([^`]*[a-z] [a-z][^`]*)`", line.split("|")[1]):
            for part in (p.strip() for p in phrase.split("...")):
                if part and not part.startswith("selfcal ") and part not in sources:
                    problem(f"docs/troubleshooting.md: `{part}` is not a message of the program")
    print(f"troubleshooting: {len(values)} exit codes, {len(outcomes)} outcome words checked")


def main():
    real = make_real_files()
    check_examples(real)
    check_written_keys_documented(real)
    check_command_lines()
    check_troubleshooting()
    if problems:
        print(f"{len(problems)} problem(s)")
        return 1
    print("every documented example and command line matches the program")
    return 0


if __name__ == "__main__":
    sys.exit(main())
