"""Why a mutant that selfcal accepted (exit 0) is a valid input, or that it is not explained (a finding).

Both the seed and the mutant are parsed by a strict reader of this script (YAML without duplicate keys,
JSON without duplicate keys or NaN, XML, the journal's framing and CRC, CSV numbers). Then:
  1. the same data: the mutation was semantics-preserving (white space, a comment, line ends, a byte order
     mark, the spelling of a number, key order);
  2. otherwise every difference must fall under a stated rule: free text, an optional key removed, a list
     of records shortened, repeated or reordered, a joint inside the robot config's limits, a finite
     measured value within 10x of the seed's magnitude, a report or study document of its format and
     version (`report` only renders it), a torn journal tail (documented as ignored), records of the
     journal's motion progress removed, repeated or reordered (no reader uses them beyond their fields),
     a URDF's links and joints reordered (sets, not lists), a URDF's effort and velocity limits (not read);
  3. anything else, including a mutant the strict reader refuses, is unexplained.
"""
import json
import math
import os
import re
import xml.etree.ElementTree as ET
import zlib

import yaml

FREE_TEXT = {"description", "source", "planner", "comment", "note", "notes", "software_version", "title", "provenance"}
OPTIONAL = {
    "trajectory": {"robot", "description", "planner"},
    "targets": {"robot", "seed_deg", "seed_rad"},
    "robot_config": {"source", "name", "home_deg"},
    "calibrated_model": {"source", "intrinsics_stddev"},
    "urdf": {"<origin>", "<inertial>", "<visual>", "<collision>", "<dynamics>", "<safety_controller>",
             "<calibration>", "<material>", "<mass>", "<inertia>", "<geometry>", "@name"},
}
RECORD_LISTS = {"poses_deg", "poses_rad", "targets", "samples", "observations", "poses", "rows", "images", "joints",
                "dots", "scene_dots_mm"}
# The journal's records of the motion's progress: ReadSessionLog checks their fields only (samples.cc), and
# a resume or a revisit writes them again for a pose, so any number of them in any order is a journal.
PROGRESS_RECORDS = {"move_started", "move_done", "settled"}
MEASURED = re.compile(r"(_mm|_m|_deg|_rad|_px|^u$|^v$|^uv|^xyz|^rpy|^quat|^rotvec|^joints|^data|^x$|^y$|^z$|"
                      r"^q[xyzw]$|^fx|^fy|^cx|^cy|^k\d|^p\d|^mu$|^rotation|^[abd]$|^alpha|^theta)")


class StrictLoader(yaml.SafeLoader):
    pass


def _mapping(loader, node, deep=False):
    loader.flatten_mapping(node)
    keys = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=True)
        if key in keys:
            raise ValueError("duplicate key %r" % (key,))
        keys.add(key)
    return loader.construct_mapping(node, deep=True)


def _any_tag(loader, suffix, node):
    if isinstance(node, yaml.MappingNode):
        return _mapping(loader, node)
    if isinstance(node, yaml.SequenceNode):
        return loader.construct_sequence(node, deep=True)
    return loader.construct_scalar(node)


StrictLoader.add_implicit_resolver(  # YAML 1.2's floats (1e3, 1.0e0), which selfcal's reader takes too
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?([0-9][0-9_]*)?\.?[0-9]+([eE][-+]?[0-9]+)$|^[-+]?[0-9]+\.[0-9]*([eE][-+]?[0-9]+)?$"),
    list("-+0123456789."))
StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)
StrictLoader.add_multi_constructor("tag:yaml.org,2002:opencv", _any_tag)
StrictLoader.add_multi_constructor("!", _any_tag)


def _text(data):
    text = data.decode("utf-8")  # invalid UTF-8 raises
    if "\x00" in text:
        raise ValueError("NUL")
    return text


def parse(fmt, data):
    if fmt in ("yaml", "opencv"):
        text = _text(data)
        if text.startswith("\ufeff"):
            text = text[1:]
        if fmt == "opencv" and text.startswith("%YAML:"):
            text = text.split("\n", 1)[1] if "\n" in text else ""
        docs = list(yaml.load_all(text, Loader=StrictLoader))
        if len(docs) != 1:
            raise ValueError("%d documents" % len(docs))
        return docs[0]
    if fmt == "json":
        def pairs(items):
            keys = [k for k, _ in items]
            if len(keys) != len(set(keys)):
                raise ValueError("duplicate key")
            return dict(items)
        return json.loads(_text(data).lstrip("\ufeff"), object_pairs_hook=pairs,
                          parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    if fmt == "xml":
        return _xml(ET.fromstring(data))
    if fmt == "journal":
        return _journal(data)
    if fmt == "csv":
        rows = []
        for row in _text(data).splitlines():
            cells = [c for c in re.split(r"[,;\s]+", row) if c]
            if cells:
                rows.append([_num(c) for c in cells])
        return {"rows": rows}
    raise ValueError(fmt)


def _num(cell):
    try:
        return float(cell)
    except ValueError:
        return cell


def _xml(e, depth=0):
    """An element as {"@attr": value, "#text": text, "<child>": [elements]}: a URDF's or ViSP file's tree
    (below 100 levels: deeper ones are one marker, which no rule explains)."""
    if depth > 100:
        return {"#deeper-than-100-levels": True}
    out = {"@" + k: v for k, v in e.attrib.items()}
    if (e.text or "").strip():
        out["#text"] = e.text.strip()
    for c in e:
        out.setdefault("<%s>" % c.tag, []).append(_xml(c, depth + 1))
    return out


def _journal(data):
    records, lines = [], data.split(b"\n")
    for i, line in enumerate(lines):
        if not line and i == len(lines) - 1:
            break
        m = re.match(rb"^J1 ([0-9a-f]{8}) ([0-9a-f]{8}) (.*)$", line, re.S)
        ok = bool(m) and int(m.group(1), 16) == len(m.group(3)) and int(m.group(2), 16) == zlib.crc32(m.group(3)) & 0xffffffff
        if not ok:
            if i == len(lines) - 1 or (i == len(lines) - 2 and not lines[-1]):
                return {"records": records, "torn_tail": True}
            raise ValueError("bad record %d" % (i + 1))
        records.append(parse("json", m.group(3)))
    return {"records": records, "torn_tail": False}


def flatten(value, path=()):
    if isinstance(value, dict):
        out = {path + ("{}",): len(value)}
        for k, v in value.items():
            out.update(flatten(v, path + (str(k),)))
        return out
    if isinstance(value, list):
        out = {path + ("[]",): len(value)}
        for i, v in enumerate(value):
            out.update(flatten(v, path + (i,)))
        return out
    return {path: value}


def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _keys_of(path):
    return [p for p in path if isinstance(p, str) and p not in ("{}", "[]")]


def _joint_limits(ctx, kind, path):
    """(min_deg, max_deg) of the joint a trajectory value is, from the robot config of the seed."""
    robot = ctx.get("current_robot")
    if not robot or not os.path.isfile(robot):
        return None
    try:
        joints = yaml.safe_load(open(robot))["joints"]
        j = path[-1]
        return float(joints[j]["min_deg"]), float(joints[j]["max_deg"])
    except (KeyError, IndexError, TypeError, ValueError):
        return None


def _plausible(old, new):
    """A measured value, changed to a finite one of the same sign within 10x of the seed's magnitude."""
    return math.isfinite(new) and abs(new) <= 10 * max(abs(old), 1.0) and \
        (old == 0 or new == 0 or (old > 0) == (new > 0) or abs(old) < 1e-3)


def _rule_for_value(kind, ctx, path, old, new):
    keys = _keys_of(path)
    last = keys[-1] if keys else ""
    if any(k in FREE_TEXT for k in keys):
        return "free text key `%s`" % last
    if kind.name == "urdf" and "<limit>" in keys and last in ("@effort", "@velocity"):
        return "a URDF joint's effort or velocity limit (selfcal reads neither)"
    if kind.name == "tracker" and isinstance(path[-1], int) and _is_number(new) and math.isfinite(new):
        if 9 <= path[-1] <= 14:
            return "an unused column of a tracker row (10-15: read and ignored, io/fanuc_tracker_csv.h)"
        if 15 <= path[-1] <= 20 and -720 <= new <= 720:
            return "a joint reading inside the reader's range [-720, 720] deg"
    if kind.name == "visp_pose" and "data" in keys and _is_number(new) and math.isfinite(new) and \
            abs(new) <= 10 * max(abs(old), 1.0):
        return "a component of a pose vector (t in m, theta-u in rad), finite, of either sign, within 10x of the seed's"
    if isinstance(old, str) and isinstance(new, str) and last.startswith("@") or last == "#text":
        a, b = old.split(), new.split()
        try:
            pairs = [(float(x), float(y)) for x, y in zip(a, b)]
        except ValueError:
            pairs = None
        if pairs is not None:
            if len(a) != len(b) or not all(_plausible(x, y) for x, y in pairs):
                return None
            return "a finite geometric or camera value within 10x of the seed's (`%s`)" % "/".join(keys[-2:])
    if kind.name == "observations" and last == "id" and isinstance(new, str) and new.strip():
        return "a pose's id is a label: any non-empty one"
    if kind.name == "urdf" and "<joint>" in keys and last == "@name" and isinstance(new, str) and new and \
            ctx.get("seed_text", b"").count(('"%s"' % old).encode()) == 1:
        return "the name of a URDF joint no element names (a label)"
    if kind.name == "calibrated_model" and "parameters" in keys and last.endswith(("_deg", "_rad")) and \
            _is_number(new) and math.isfinite(new) and abs(new if last.endswith("_deg") else math.degrees(new)) <= 720:
        return ("an angle of the identified vector `parameters` within the reader's [-720, 720] deg: any angle is a "
                "rotation (195 deg turns as -165 deg does), and the vector is a record of the solve: compensate "
                "computes from the model the corrections are folded into (calibrated-model-format.md)")
    if kind.name == "calibrated_model" and "intrinsics_stddev" in keys and _is_number(new) and 0 <= new <= 1e6:
        return "an intrinsics standard deviation in its documented range [0, 1e6] (reported, not used by compensate)"
    if kind.name == "calibrated_model" and "parameters" in keys and _is_number(new) and abs(new) < 1e-12:
        return "a kinematic parameter set to zero (below 1e-12 of its unit): a valid parameter"
    if kind.name == "camera_visp" and "<name>" in keys and ctx.get("seed_name") == "cam_visp.xml":
        return "the name of the only camera of a file read without --camera-name"
    if kind.name == "ros_pose" and last in ("qx", "qy", "qz", "qw") and _is_number(new) and isinstance(ctx.get("new_doc"), dict):
        try:
            norm = math.sqrt(sum(float(ctx["new_doc"][k]) ** 2 for k in ("qx", "qy", "qz", "qw")))
        except (KeyError, TypeError, ValueError):
            norm = 0
        if abs(norm - 1) <= 1e-3:
            return "a unit quaternion (norm within 1e-3 of 1, detect.md)"
        return None
    if not (_is_number(old) and _is_number(new)):
        return None
    if not math.isfinite(float(new)) if abs(new) < 1e308 else True:
        return None
    if kind.name in ("report_json", "study_json"):
        return "a finite number of a report: report only renders it"
    if kind.name == "trajectory" and "scene_dots_mm" in keys and _plausible(old, new):
        return "a scene dot's coordinate, finite and within 10x of the seed's (any such dot is a valid scene)"
    if kind.name == "trajectory" and last in ("poses_deg", "poses_rad"):
        limits = _joint_limits(ctx, kind, path)
        if limits:
            deg = new if last == "poses_deg" else math.degrees(new)
            if limits[0] <= deg <= limits[1]:
                return "a joint inside the robot config's limits [%g, %g] deg" % limits
        return None
    if kind.name in ("observations", "tracker", "robot_config", "calibrated_model", "camera_opencv", "camera_visp",
                     "ros_pose", "visp_pose", "targets", "journal", "session_inputs") and \
            (MEASURED.search(last) or kind.name in ("tracker", "journal") or isinstance(path[-1], int)):
        if _plausible(old, new):
            return "a finite measured or geometric value within 10x of the seed's (any such value is a valid measurement)"
    return None


def _edited_record(kind, ctx, path, a, b):
    """The rules under which record b is record a with some values changed (the same keys, each changed value
    under a value rule), or None."""
    fa, fb = flatten(a), flatten(b)
    if set(fa) != set(fb):
        return None
    rules = set()
    for sub in fa:
        if fa[sub] != fb[sub]:
            rule = _rule_for_value(kind, ctx, path + sub, fa[sub], fb[sub])
            if not rule:
                return None
            rules.add(rule)
    return rules


def _record_list_change(old, new, key_path, kind=None, ctx=None):
    """None when the list at key_path is not a list of the seed's records removed, repeated or reordered; else
    the value rules (maybe none) under which each record that is not one of the seed's is one of the seed's
    with values changed: the closest of the records the mutant lacks, each matched once (a row deleted and
    another's reading changed are two rules at once)."""
    def get(doc, path):
        for p in path:
            doc = doc[p]
        return doc
    try:
        a, b = get(old, key_path), get(new, key_path)
    except (KeyError, IndexError, TypeError):
        return None
    if not isinstance(a, list) or not isinstance(b, list) or not b:
        return None
    norm = lambda v: json.dumps(v, sort_keys=True, default=str)  # noqa: E731
    items = {norm(x) for x in a}
    kept = {norm(x) for x in b}
    unused = [x for x in a if norm(x) not in kept]  # the seed's records the mutant lacks: the edited ones' candidates
    rules = set()
    for j, x in enumerate(b):
        if norm(x) in items:
            continue
        if kind is None:
            return None
        # the closest candidate (fewest values changed) whose changes the rules explain
        best = None
        for n, candidate in enumerate(unused):
            fc, fx = flatten(candidate), flatten(x)
            changed = sum(1 for q in set(fc) | set(fx) if fc.get(q) != fx.get(q))
            if best is None or changed < best[0]:
                match = _edited_record(kind, ctx, key_path + (j,), candidate, x)
                if match is not None:
                    best = (changed, n, match)
        if best is None:
            return None
        del unused[best[1]]
        rules |= best[2]
    return rules


def _normal(data):
    data = data[3:] if data.startswith(b"\xef\xbb\xbf") else data
    return b"\n".join(line.rstrip(b" \t\r") for line in data.split(b"\n"))

UNIT_PAIRS = {"_mm": ("_m", 1e-3), "_m": ("_mm", 1e3), "_deg": ("_rad", math.pi / 180), "_rad": ("_deg", 180 / math.pi)}


def _same_in_other_unit(path, value, here, there):
    """The key at `path` of document `here` is absent from `there`, which gives the same quantity under the
    key's other unit (`a_mm` / `a_m`, `_deg` / `_rad`) with the same value converted (a reader takes both)."""
    if not path or not isinstance(path[-1], str) or not _is_number(value):
        return False
    for suffix, (other, factor) in UNIT_PAIRS.items():
        if path[-1].endswith(suffix):
            twin = path[:-1] + (path[-1][:-len(suffix)] + other,)
            v = there.get(twin)
            if twin not in here and _is_number(v) and math.isclose(v, value * factor, rel_tol=1e-9, abs_tol=1e-12):
                return True
    return False


def _journal_kept(records):
    """The records a reader uses, in order, an exact repeat of one dropped (a repeated sample_accepted,
    frame_written or pose_planned must agree with the first and the first counts: samples.h)."""
    kept, seen = [], set()
    for r in records:
        if isinstance(r, dict) and r.get("type") in PROGRESS_RECORDS:
            continue
        key = json.dumps(r, sort_keys=True)
        if key in seen and isinstance(r, dict) and r.get("type") in ("sample_accepted", "frame_written", "pose_planned"):
            continue
        seen.add(key)
        kept.append(r)
    return kept


def _urdf_as_sets(doc):
    """A URDF's tree with <robot>'s <link> and <joint> lists sorted by name: their order is not data."""
    if not isinstance(doc, dict):
        return doc
    out = dict(doc)
    for tag in ("<link>", "<joint>"):
        if isinstance(out.get(tag), list):
            out[tag] = sorted(out[tag], key=lambda e: json.dumps(e, sort_keys=True))
    return out


def _document_rule(kind, old, new):
    """A rule about the whole document, or "": see the module's docstring."""
    if kind.name in ("report_json", "study_json") and isinstance(old, dict) and isinstance(new, dict) and \
            all(new.get(k) == old.get(k) for k in ("format", "version")):
        return ("a %s document of the seed's format and version: `report` renders what it is given (a key it "
                "lacks leaves its figure or row out, every text is escaped: report/html_report.h) and computes "
                "nothing from it" % ("report" if kind.name == "report_json" else "study"))
    kept_old = _journal_kept(old["records"]) if kind.fmt == "journal" else None
    if kind.fmt == "journal" and not old["torn_tail"] and \
            (_journal_kept(new["records"]) == kept_old if not new["torn_tail"] else
             _journal_kept(new["records"]) == kept_old[:len(_journal_kept(new["records"]))]):
        return ("only records of the motion's progress (move_started, move_done, settled) removed, repeated or "
                "reordered, or a sample, frame or plan record repeated exactly: the records a reader uses are the "
                "same, in the same order%s" % (" up to a torn tail (ignored, session-format.md)" if new["torn_tail"] else ""))
    if kind.name == "urdf" and _urdf_as_sets(old) == _urdf_as_sets(new):
        return "a URDF's links or joints reordered: they are sets, their order is not data"
    return ""


def explain(kind, ctx, original, mutant, ops):
    names = [o["desc"].split(" ")[0] for o in ops]
    try:
        old = parse(kind.fmt, original)
    except Exception as e:  # noqa: BLE001
        return True, "seed not parsed by this script's reader (%s): not judged" % type(e).__name__
    if kind.fmt != "journal" and {o["op"] for o in ops} <= {"trailing_space", "crlf", "bom"} and _normal(mutant) == _normal(original):
        return True, "semantics-preserving (%s): the same text but for white space at line ends, line ends or a BOM" % \
            ", ".join(sorted({o["op"] for o in ops}))
    if len(mutant) > 2 * len(original) + (1 << 20):
        huge = [o for o in ops if o["op"] == "huge"]
        line = huge[0].get("line", b"x") if huge else b"x"
        if huge and len(ops) == 1 and (not line.strip() or line.strip().startswith((b"#", b"<!--"))):
            return True, "semantics-preserving (huge): a comment or blank line repeated"
        if True:  # a comment's line inside it, a progress record or a report's list item repeated
            try:
                same = _document_rule(kind, old, parse(kind.fmt, mutant)) or \
                    ("the same data after parsing" if parse(kind.fmt, mutant) == old else "")
            except Exception:  # noqa: BLE001
                same = ""
            if same:
                return True, "%s (a file of %.1f MiB: %s)" % (same, len(mutant) / 2.0 ** 20, ", ".join(names))
        return False, "a file of %.1f MiB accepted (%s)" % (len(mutant) / 2.0 ** 20, ", ".join(names))
    try:
        try:
            new = parse(kind.fmt, mutant)
        except Exception:  # noqa: BLE001
            if "trailing_space" not in {o["op"] for o in ops} or kind.fmt == "journal":
                raise
            new = parse(kind.fmt, _normal(mutant))  # PyYAML refuses a tab at a flow line's end; it is not data
    except Exception as e:  # noqa: BLE001
        return False, "not a valid %s file for a strict reader: %s" % (kind.fmt, str(e).splitlines()[0][:160] if str(e) else type(e).__name__)
    document_rule = _document_rule(kind, old, new)
    if document_rule:
        return True, document_rule
    if kind.fmt == "journal" and new["torn_tail"] and new["records"] == old["records"][:len(new["records"])]:
        return True, "torn journal tail: the records before it unchanged (a torn tail is ignored, session-format.md)"
    if old == new:
        preserving = {"trailing_space", "comment", "crlf", "bom", "respell_number", "reorder_json"}
        ops_set = {o["op"] for o in ops}
        if ops_set <= preserving:
            return True, "semantics-preserving (%s): the same data" % ", ".join(sorted(ops_set))
        return True, "the same data after parsing (%s)" % ", ".join(sorted(ops_set))
    fa, fb = flatten(old), flatten(new)
    ctx = dict(ctx, new_doc=new, seed_text=original)
    reasons = set()
    differing = (set(fa) ^ set(fb)) | {q for q in fa if q in fb and fa[q] != fb[q]}
    covered = []
    for p in fa:
        if len(p) >= 2 and p[-1] == "[]" and p[-2] in RECORD_LISTS and any(q[:len(p) - 1] == p[:-1] for q in differing):
            edits = _record_list_change(old, new, p[:-1], kind, ctx)
            if edits is not None:
                covered.append(p[:-1])
                reasons.add("records of `%s` removed, repeated or reordered: a list of any length (%s)%s" % (
                    p[-2], ", ".join(names), "; within a record: " + "; ".join(sorted(edits)) if edits else ""))
    for path in sorted(set(fa) | set(fb), key=str):
        a, b = fa.get(path, None), fb.get(path, None)
        if path in fa and path in fb and a == b:
            continue
        if any(path[:len(prefix)] == prefix for prefix in covered):
            continue
        if kind.name == "urdf" and path and path[0] in ("<transmission>", "<gazebo>"):
            reasons.add("inside <transmission> or <gazebo> (ros_control's and Gazebo's: selfcal reads neither)")
            continue
        keys = _keys_of(path)
        if path not in fb:
            if kind.name == "camera_visp" and "<name>" in keys and ctx.get("seed_name") == "cam_visp.xml":
                reasons.add("the name of the only camera of a file read without --camera-name removed")
                continue
            if _same_in_other_unit(path, a, fa, fb):
                reasons.add("`%s` given in the other unit of its quantity, the same value" % keys[-1])
                continue
            if keys and (keys[-1] in OPTIONAL.get(kind.name, ()) or keys[-1] in FREE_TEXT or
                         any(k in OPTIONAL.get(kind.name, ()) for k in keys)):
                reasons.add("optional key `%s` removed" % keys[-1])
                continue
            if path[-1] == "{}" and any(k in OPTIONAL.get(kind.name, ()) for k in keys):
                continue
            if path[-1] in ("{}",):
                continue
            return False, "key %s removed and the reader did not ask for it" % "/".join(map(str, path))
        if path not in fa:
            if path[-1] == "{}" or _same_in_other_unit(path, b, fb, fa):
                continue
            if kind.name == "urdf" and len(path) >= 2 and path[0].startswith("<") and \
                    path[0] not in ("<link>", "<joint>", "<material>") and not any("deeper" in str(p) for p in path):
                reasons.add("an element URDF does not define, directly under <robot> (ignored, like <gazebo>)")
                continue
            return False, "key %s added and accepted" % "/".join(map(str, path))
        if path[-1] == "{}":
            continue
        rule = _rule_for_value(kind, ctx, path, a, b)
        if not rule:
            return False, "value of %s changed %r -> %r and accepted" % ("/".join(map(str, path)), a, b)
        reasons.add(rule)
    return True, "; ".join(sorted(reasons)) or "no difference"
