#!/usr/bin/python3
"""report.json against its documented schema (docs/report.schema.json, docs/report-format.md).

Runs the selfcal binary as a user would: `simulate --points` (bundle, accepted), `calibrate --method paper`
on its observations (paper, accepted), `calibrate --camera-file` with the principal point and the lens freed
(bundle, accepted), `simulate --points --flat-sheet` (bundle, accepted; the ambiguous planar pairs' rival
solutions and plane normals reported, one of each pair's two normals the resolved pairs' plane), and `calibrate` on a file with too few poses (exit 3, not accepted, no model), then validates every report.json with python3-jsonschema and checks the rules the
schema cannot state: the top level repeats the chosen method's figures, and no key carries mm or degrees.

  report_schema_test.py SELFCAL_BINARY SOURCE_DIR
"""
import json
import math
import os
import subprocess
import sys
import tempfile

import jsonschema
import yaml


def run(binary, args, cwd):
    p = subprocess.run([binary] + args, cwd=cwd, capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def keys(node, path=""):
    if isinstance(node, dict):
        for k, v in node.items():
            yield path + "/" + k
            yield from keys(v, path + "/" + k)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from keys(v, f"{path}/{i}")


def check(report_path, schema, expect_method, expect_accepted, failures):
    with open(report_path) as f:
        report = json.load(f)
    validator = jsonschema.Draft202012Validator(schema)
    for error in sorted(validator.iter_errors(report), key=lambda e: list(e.path)):
        failures.append(f"{report_path}: /{'/'.join(map(str, error.path))}: {error.message}")
    if report.get("method") != expect_method:
        failures.append(f"{report_path}: method {report.get('method')!r}, expected {expect_method!r}")
    if report.get("accepted") != expect_accepted:
        failures.append(f"{report_path}: accepted {report.get('accepted')!r}, expected {expect_accepted!r}")
    chosen = report.get("methods", {}).get(expect_method, {})
    for key in ("fx_px", "verification", "predicted_3d_error"):
        if report.get(key) != chosen.get(key):
            failures.append(f"{report_path}: top-level {key} is not methods.{expect_method}.{key}")
    for k in keys(report):
        if k.endswith(("_mm", "_deg")):
            failures.append(f"{report_path}: key {k} is not SI")
    return report


def angle(a, b):
    dot = sum(x * y for x, y in zip(a, b)) / math.sqrt(sum(x * x for x in a) * sum(y * y for y in b))
    return math.degrees(math.acos(max(-1.0, min(1.0, dot))))


def check_flat_pairs(report, failures):
    pairs = report.get("methods", {}).get("paper", {}).get("pose_measurements", [])
    ambiguous = [m for m in pairs if m.get("outcome") == "ambiguous_pose"]
    resolved = [m["plane_normal_in_reference_cam"] for m in pairs
                if m.get("outcome") == "success" and m.get("plane_normal_in_reference_cam")]
    if not ambiguous or not resolved:
        failures.append(f"flat sheet: {len(ambiguous)} ambiguous and {len(resolved)} resolved planar pairs, expected both")
        return
    for m in ambiguous:
        rival = m.get("rival") or {}
        normals = [m.get("plane_normal_in_reference_cam"), rival.get("plane_normal_in_reference_cam")]
        if None in normals or not rival.get("rotvec_rad") or not rival.get("translation_direction"):
            failures.append(f"flat sheet: ambiguous pair {m.get('pose')} lacks its rival or a plane normal")
        elif min(angle(n, resolved[0]) for n in normals) > 2.0:
            failures.append(f"flat sheet: neither plane of pair {m.get('pose')} is the resolved pairs' plane")


def main():
    binary, source = sys.argv[1], sys.argv[2]
    with open(os.path.join(source, "docs", "report.schema.json")) as f:
        schema = json.load(f)
    jsonschema.Draft202012Validator.check_schema(schema)
    failures = []
    with tempfile.TemporaryDirectory(prefix="selfcal-schema-") as tmp:
        sim = os.path.join(tmp, "sim")
        code, out = run(binary, ["simulate", "--points", "--seed", "2", "--out", sim], source)
        if code != 0:
            print(out)
            failures.append(f"simulate exited {code}")
        else:
            check(os.path.join(sim, "report.json"), schema, "bundle", True, failures)
            paper = os.path.join(tmp, "paper")
            code, out = run(binary, ["calibrate", os.path.join(sim, "observations.yaml"), "--method", "paper",
                                     "--out", paper], source)
            # The paper's model measures the check distances worse than the nominal one here: refused (6).
            if code != 6:
                failures.append(f"calibrate --method paper exited {code}, expected 6: {out[-2000:]}")
            check(os.path.join(paper, "report.json"), schema, "paper", False, failures)
            # The camera from an OpenCV file, the principal point and the lens estimated.
            with open(os.path.join(sim, "observations.yaml")) as f:
                camera = yaml.safe_load(f)["camera"]
            camera_file = os.path.join(tmp, "camera.yaml")
            with open(camera_file, "w") as f:
                fx, fy = camera["fx_px"], camera["fx_px"] * camera.get("mu", 1.0)
                f.write("%YAML:1.0\n---\n"
                        f"image_width: {camera['width_px']}\nimage_height: {camera['height_px']}\n"
                        "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                        f"   data: [ {fx}, 0., {camera['cx_px']}, 0., {fy}, {camera['cy_px']}, 0., 0., 1. ]\n"
                        "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
                        f"   data: [ {camera.get('k1', 0.0)}, 0., 0., 0., 0. ]\n")
            lens = os.path.join(tmp, "lens")
            code, out = run(binary, ["calibrate", os.path.join(sim, "observations.yaml"), "--camera-file", camera_file,
                                     "--free", "kinematics,camera,fx,cx,cy,lens", "--out", lens], source)
            if code != 0:
                failures.append(f"calibrate --camera-file exited {code}: {out[-2000:]}")
            report = check(os.path.join(lens, "report.json"), schema, "bundle", True, failures)
            estimated = [k for k, v in report.get("methods", {}).get("bundle", {}).get("intrinsics", {}).items()
                         if v.get("estimated")]
            if sorted(estimated) != sorted(["fx", "cx", "cy", "k1", "k2", "p1", "p2", "k3"]):
                failures.append(f"lens report: estimated intrinsics {estimated}")
            if (report.get("input", {}).get("camera_file") or {}).get("path") != camera_file:
                failures.append("lens report: input.camera_file does not name the camera file")
            # A flat dot sheet: the paper pipeline's planar pairs stay ambiguous; each reports both solutions'
            # plane normals in the reference camera, and one of the two is the plane every pair sees.
            flat = os.path.join(tmp, "flat")
            code, out = run(binary, ["simulate", "--points", "--flat-sheet", "--seed", "2", "--out", flat], source)
            if code != 0:
                failures.append(f"simulate --flat-sheet exited {code}: {out[-2000:]}")
            else:
                check_flat_pairs(check(os.path.join(flat, "report.json"), schema, "bundle", True, failures), failures)
            # Too few poses: exit 3, a report that says why, no model.
            with open(os.path.join(sim, "observations.yaml")) as f:
                observations = yaml.safe_load(f)
            observations["poses"] = observations["poses"][:3]
            few = os.path.join(tmp, "few.yaml")
            with open(few, "w") as f:
                yaml.safe_dump(observations, f)
            out_few = os.path.join(tmp, "few")
            code, out = run(binary, ["calibrate", few, "--out", out_few], source)
            if code != 3:
                failures.append(f"calibrate on 3 poses exited {code}, expected 3: {out[-2000:]}")
            report = check(os.path.join(out_few, "report.json"), schema, "bundle", False, failures)
            if report.get("exit_code") != 3:
                failures.append(f"few.yaml report exit_code {report.get('exit_code')}, expected 3")
            if os.path.exists(os.path.join(out_few, "calibrated_model.yaml")):
                failures.append("a model was written for a result that was not accepted")
    for f in failures:
        print("FAIL:", f)
    print(f"report schema: {len(failures)} problem(s) in 5 reports" if failures else "report schema: 5 reports valid")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
