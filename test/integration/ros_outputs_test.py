#!/usr/bin/python3
"""The calibration's ROS outputs read by readers that are not selfcal's (docs/camera-files.md).

Runs `selfcal simulate --points` on the UR5e as a user would, then reads camera_info.yaml with Python's yaml
(python3-yaml) against the keys and values of ROS's camera_calibration_parsers format (image_width,
image_height, camera_name, camera_matrix, distortion_model plumb_bob, distortion_coefficients 1x5,
rectification_matrix identity, projection_matrix [K | 0]) and the calibrated camera of calibrated_model.yaml,
and with camera_calibration_parsers itself (Debian's python3-camera-calibration-parsers, ROS 1's
readCalibration over the C++ parser) when it is installed, which must return the same sensor_msgs/CameraInfo.
The OpenCV file of --write-camera-opencv must stay refused by that parser (it is OpenCV's format). The UR5e's
ur_calibrated_kinematics.yaml is read the same way against ur_description's keys, and its chain, built as
ur_description's xacro builds it, against the forward kinematics of calibrated_model.yaml computed here with
numpy (not selfcal's code) at 1000 random joint vectors, to 1e-9. camera_static_transform.launch.py is parsed
by Python's ast (ROS 2 is not installed here, so launch and launch_ros are not imported): one launch_ros Node of
tf2_ros' static_transform_publisher with the named arguments of ROS 2 Humble and later, whose translation
and quaternion equal calibrated_model.yaml's flange_from_cam to 1e-9 and camera_static_transform.yaml's
numbers and frames exactly (the same (x, y, z, w) order, w >= 0).

  ros_outputs_test.py SELFCAL_BINARY SOURCE_DIR
"""
import ast
import math
import os
import random
import re
import subprocess
import sys
import tempfile

import numpy
import yaml

KEYS = ["image_width", "image_height", "camera_name", "camera_matrix", "distortion_model",
        "distortion_coefficients", "rectification_matrix", "projection_matrix"]


def matrix(doc, key, rows, cols, failures):
    node = doc.get(key)
    if not isinstance(node, dict) or sorted(node) != ["cols", "data", "rows"]:
        failures.append(f"{key}: {node!r} is not a {{rows, cols, data}} map")
        return None
    if node["rows"] != rows or node["cols"] != cols or len(node["data"]) != rows * cols:
        failures.append(f"{key}: {node['rows']}x{node['cols']} with {len(node['data'])} values, expected {rows}x{cols}")
        return None
    return [float(v) for v in node["data"]]


def close(a, b, tol=1e-12):
    return len(a) == len(b) and all(abs(x - y) <= tol * max(1.0, abs(y)) for x, y in zip(a, b))


def check_camera_info(path, camera, failures):
    with open(path) as f:
        doc = yaml.safe_load(f)
    if list(doc) != KEYS:
        failures.append(f"{path}: keys {list(doc)}, expected {KEYS}")
    if doc.get("image_width") != camera["width_px"] or doc.get("image_height") != camera["height_px"]:
        failures.append(f"{path}: image {doc.get('image_width')}x{doc.get('image_height')}")
    if doc.get("distortion_model") != "plumb_bob":
        failures.append(f"{path}: distortion_model {doc.get('distortion_model')!r}")
    fx, fy = camera["fx_px"], camera["fx_px"] * camera.get("mu", 1.0)
    cx, cy = camera["cx_px"], camera["cy_px"]
    k = [fx, 0, cx, 0, fy, cy, 0, 0, 1]
    d = [camera.get(n, 0.0) for n in ("k1", "k2", "p1", "p2", "k3")]
    expected = {"camera_matrix": (3, 3, k), "distortion_coefficients": (1, 5, d),
                "rectification_matrix": (3, 3, [1, 0, 0, 0, 1, 0, 0, 0, 1]),
                "projection_matrix": (3, 4, [fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0])}
    for key, (rows, cols, values) in expected.items():
        data = matrix(doc, key, rows, cols, failures)
        if data is not None and not close(data, values):
            failures.append(f"{path}: {key} {data}, expected {values}")
    return k, d


def check_with_ros_parser(path, opencv_path, k, d, failures):
    try:
        import camera_calibration_parsers
    except ImportError:
        print("camera_calibration_parsers is not installed (Debian: python3-camera-calibration-parsers): "
              "checked with python3-yaml only")
        return
    read = camera_calibration_parsers.readCalibration(path)
    if read is None:
        failures.append(f"{path}: camera_calibration_parsers.readCalibration refused it")
        return
    name, info = read
    if name != "camera" or info.distortion_model != "plumb_bob" or not close(list(info.K), k) or \
            not close(list(info.D), d) or not close(list(info.R), [1, 0, 0, 0, 1, 0, 0, 0, 1]):
        failures.append(f"{path}: camera_calibration_parsers read {name!r} {info}")
    print(f"camera_calibration_parsers read {path}: K {list(info.K)}, D {list(info.D)}")
    if camera_calibration_parsers.readCalibration(opencv_path) is not None:
        failures.append(f"{opencv_path}: camera_calibration_parsers took the OpenCV file (it lacks R and P)")


def rot(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    m = {"x": [[1, 0, 0], [0, c, -s], [0, s, c]], "y": [[c, 0, s], [0, 1, 0], [-s, 0, c]],
         "z": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[axis]
    t = numpy.eye(4)
    t[:3, :3] = m
    return t


def trans(x, y, z):
    t = numpy.eye(4)
    t[:3, 3] = [x, y, z]
    return t


def rpy(roll, pitch, yaw):  # URDF's and selfcal's configs': R = Rz(yaw) Ry(pitch) Rx(roll)
    return rot("z", yaw) @ rot("y", pitch) @ rot("x", roll)


def model_flange(model, q):
    """base_from_flange of calibrated_model.yaml (mm, deg): base_from_link0 * prod Rx Tx Ry Rz(q + theta) Tz * tail."""
    def transform(node):
        x, y, z = (v / 1000 for v in node["xyz_mm"])
        return trans(x, y, z) @ rpy(*(math.radians(v) for v in node["rpy_deg"]))
    t = transform(model["base_from_link0"])
    for joint, qi in zip(model["joints"], q):
        t = t @ rot("x", math.radians(joint["alpha_deg"])) @ trans(joint["a_mm"] / 1000, 0, 0) @ \
            rot("y", math.radians(joint.get("beta_deg", 0))) @ \
            rot("z", qi + math.radians(joint.get("theta_offset_deg", 0))) @ trans(0, 0, joint["d_mm"] / 1000)
    return t @ transform(model["link_n_from_flange"])


def xacro_chain(kinematics, q):
    """base_link_inertia -> wrist_3_link as ur_description's xacro builds it from the kinematics file."""
    t = numpy.eye(4)
    for name, qi in zip(("shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"), q):
        j = kinematics[name]
        t = t @ trans(j["x"], j["y"], j["z"]) @ rpy(j["roll"], j["pitch"], j["yaw"]) @ rot("z", qi)
    return t


def check_ur_kinematics(path, model, failures):
    """ur_calibrated_kinematics.yaml by python3-yaml against ur_description's keys, and its chain against the
    calibrated model's forward kinematics computed here from calibrated_model.yaml, at 1000 random joints."""
    with open(path) as f:
        kinematics = yaml.safe_load(f)["kinematics"]
    joints = ["shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"]
    if list(kinematics) != joints + ["hash"]:
        failures.append(f"{path}: keys {list(kinematics)}")
        return
    for name in joints:
        if sorted(kinematics[name]) != sorted(["x", "y", "z", "roll", "pitch", "yaw"]) or \
                not all(isinstance(v, (int, float)) for v in kinematics[name].values()):
            failures.append(f"{path}: {name}: {kinematics[name]}")
            return
    if not re.fullmatch(r"calib_[0-9]+", str(kinematics["hash"])):
        failures.append(f"{path}: hash {kinematics['hash']!r}")
    rng = random.Random(3)
    worst = 0.0
    for _ in range(1000):
        q = [rng.uniform(math.radians(j["min_deg"]), math.radians(j["max_deg"])) for j in model["joints"]]
        a, b = xacro_chain(kinematics, q), model_flange(model, q)
        worst = max(worst, float(numpy.abs(a[:3, 3] - b[:3, 3]).max()), float(numpy.abs(a[:3, :3] - b[:3, :3]).max()))
    print(f"{path}: ur_description's chain against calibrated_model.yaml at 1000 random joints: worst {worst:.3g}")
    if worst > 1e-9:
        failures.append(f"{path}: the xacro's chain differs from the calibrated model by {worst:.3g}")


def transform_of(node):
    """A calibrated_model.yaml transform (xyz_mm + rpy_deg, or xyz_m + rotation) as a 4x4 matrix."""
    if "xyz_m" in node:
        t = trans(*node["xyz_m"])
        t[:3, :3] = numpy.array(node["rotation"], dtype=float)
        return t
    x, y, z = (v / 1000 for v in node["xyz_mm"])
    return trans(x, y, z) @ rpy(*(math.radians(v) for v in node["rpy_deg"]))


def quaternion_matrix(qx, qy, qz, qw):  # Hamilton, (x, y, z, w) as ROS's geometry_msgs/Quaternion
    return numpy.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                        [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                        [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])


def launch_node(path, failures):
    """The keyword arguments of the one launch_ros Node call in generate_launch_description, as literals."""
    with open(path) as f:
        tree = ast.parse(f.read(), filename=path)
    imports = {(n.module, a.name) for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for a in n.names}
    if not {("launch", "LaunchDescription"), ("launch_ros.actions", "Node")} <= imports:
        failures.append(f"{path}: imports {sorted(imports)}")
    functions = [n.name for n in tree.body if isinstance(n, ast.FunctionDef)]
    if functions != ["generate_launch_description"]:
        failures.append(f"{path}: functions {functions}")
    nodes = [n for n in ast.walk(tree) if isinstance(n, ast.Call) and getattr(n.func, "id", None) == "Node"]
    if len(nodes) != 1:
        failures.append(f"{path}: {len(nodes)} Node calls, expected 1")
        return None
    return {k.arg: ast.literal_eval(k.value) for k in nodes[0].keywords}


def check_launch_file(path, model, static_path, failures):
    """camera_static_transform.launch.py against calibrated_model.yaml's flange_from_cam (1e-9) and against
    camera_static_transform.yaml (the same numbers, frames and quaternion order)."""
    if not os.path.exists(path):
        failures.append(f"{path}: not written")
        return
    node = launch_node(path, failures)
    if node is None:
        return
    if node.get("package") != "tf2_ros" or node.get("executable") != "static_transform_publisher":
        failures.append(f"{path}: package {node.get('package')!r}, executable {node.get('executable')!r}")
    args = node.get("arguments", [])
    names = ["--x", "--y", "--z", "--qx", "--qy", "--qz", "--qw", "--frame-id", "--child-frame-id"]
    if not all(isinstance(a, str) for a in args) or args[0::2] != names:
        failures.append(f"{path}: arguments {args}, expected the named form {names}")
        return
    value = dict(zip(args[0::2], args[1::2]))
    x, y, z, qx, qy, qz, qw = (float(value[n]) for n in names[:7])
    with open(static_path) as f:
        static = yaml.safe_load(f)
    t, r = static["transform"]["translation"], static["transform"]["rotation"]
    if [x, y, z, qx, qy, qz, qw] != [t["x"], t["y"], t["z"], r["x"], r["y"], r["z"], r["w"]] or \
            value["--frame-id"] != static["header"]["frame_id"] or \
            value["--child-frame-id"] != static["child_frame_id"]:
        failures.append(f"{path}: {value} differs from {static_path}: {static}")
    if qw < 0 or abs(math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw) - 1) > 1e-12:
        failures.append(f"{path}: quaternion {(qx, qy, qz, qw)} is not unit with w >= 0")
    flange_from_cam = transform_of(model["flange_from_cam"])
    worst = max(float(numpy.abs(numpy.array([x, y, z]) - flange_from_cam[:3, 3]).max()),
                float(numpy.abs(quaternion_matrix(qx, qy, qz, qw) - flange_from_cam[:3, :3]).max()))
    print(f"{path}: {value['--frame-id']} -> {value['--child-frame-id']}, against calibrated_model.yaml's "
          f"flange_from_cam: worst {worst:.3g}")
    if worst > 1e-9:
        failures.append(f"{path}: differs from calibrated_model.yaml's flange_from_cam by {worst:.3g}")


def main():
    binary, source = sys.argv[1], sys.argv[2]
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "ur5e")
        opencv = os.path.join(tmp, "camera_opencv.yaml")
        args = [binary, "simulate", "--points", "--no-html", "--quiet", "--robot",
                os.path.join(source, "config/robots/ur5e.yaml"), "--trajectory",
                os.path.join(source, "config/trajectories/initial_ur5e.yaml"), "--out", out]
        p = subprocess.run(args, capture_output=True, text=True)
        if p.returncode != 0:
            print(p.stdout + p.stderr)
            return 1
        with open(os.path.join(out, "calibrated_model.yaml")) as f:
            model = yaml.safe_load(f)
        k, d = check_camera_info(os.path.join(out, "camera_info.yaml"), model["camera"], failures)
        check_ur_kinematics(os.path.join(out, "ur_calibrated_kinematics.yaml"), model, failures)
        check_launch_file(os.path.join(out, "camera_static_transform.launch.py"), model,
                          os.path.join(out, "camera_static_transform.yaml"), failures)
        p = subprocess.run([binary, "calibrate", "--no-html", "--quiet", os.path.join(out, "observations.yaml"),
                            "--out", os.path.join(tmp, "again"), "--write-camera-opencv", opencv],
                           capture_output=True, text=True)
        if p.returncode != 0 or not os.path.exists(opencv):
            failures.append("calibrate --write-camera-opencv: " + p.stdout + p.stderr)
        check_with_ros_parser(os.path.join(out, "camera_info.yaml"), opencv, k, d, failures)
    for failure in failures:
        print("FAIL: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
