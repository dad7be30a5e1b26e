"""The mutators of scripts/mutation-campaign: structure-aware (keys, values, lines, records) and byte-level.

mutate(data, fmt, rng) -> (bytes, ops): ops lists each edit as {"op": name, "desc": text}. fmt is one of
yaml, opencv, json, xml, journal, csv. Every choice comes from rng, so a seeded Random gives the same mutant.
"""
import json
import math
import re
import zlib

NUMBER = re.compile(rb"(?<![\w.])-?\d+(\.\d+)?([eE][-+]?\d+)?(?![\w.])")
YAML_KEY = re.compile(rb"^(\s*(?:- )?\{?\s*)([A-Za-z_][\w]*)(\s*:)", re.M)
JSON_KEY = re.compile(rb"\"([A-Za-z_][\w]*)\"(\s*:)")
XML_NAME = re.compile(rb"<(/?)([A-Za-z_][\w]*)")
XML_ATTR = re.compile(rb"\s([A-Za-z_][\w]*)=\"")
UNIT_SWAPS = [(b"_deg", b"_rad"), (b"_rad", b"_deg"), (b"_mm", b"_m"), (b"_m", b"_mm"), (b"_px", b"_mm"),
              (b"_m\"", b"_mm\""), (b"_s", b"_ms")]
PRESERVING = {"trailing_space", "comment", "crlf", "bom", "respell_number", "indent_flow"}


def _comment(fmt):
    return {"yaml": b"# a comment added by the mutation campaign", "opencv": b"# a comment",
            "xml": b"<!-- a comment -->", "csv": None, "json": None, "journal": None}.get(fmt)


def _lines(data):
    return data.split(b"\n")


def _join(lines):
    return b"\n".join(lines)


def _pick_number(data, rng):
    numbers = list(NUMBER.finditer(data))
    return numbers[rng.randrange(len(numbers))] if numbers else None


def _value_replacements(fmt, old):
    try:
        x = float(old)
    except ValueError:
        x = 1.0
    as_deg = "%.17g" % math.degrees(x)
    as_rad = "%.17g" % math.radians(x)
    nan, inf = (b".nan", b".inf") if fmt in ("yaml", "opencv") else (b"NaN", b"1e999")
    reps = [("nan", nan), ("inf", inf), ("-inf", b"-" + inf), ("huge", b"1e308"), ("huge-int", b"99999999999999999999999"),
            ("negative", ("%.17g" % -x).encode() if x != 0 else b"-1"), ("zero", b"0"), ("tiny", b"1e-300"),
            ("rad-for-deg", as_rad.encode()), ("deg-for-rad", as_deg.encode()), ("scaled-1000", ("%.17g" % (x * 1000)).encode()),
            ("scaled-0.001", ("%.17g" % (x / 1000)).encode()), ("nudged", ("%.17g" % (x * 1.001 + 1e-4)).encode()),
            ("string", b"\"text\""), ("list", b"[1, 2]"), ("map", b"{a: 1}" if fmt == "yaml" else b"{\"a\": 1}"),
            ("bool", b"true"), ("null", b"null"), ("empty", b""), ("hex", b"0x10"), ("int-overflow", b"18446744073709551616"),
            ("negative-zero", b"-0.0")]
    if fmt == "xml":
        reps = [r for r in reps if r[0] not in ("list", "map")]
    return reps


def m_delete_line(data, fmt, rng):
    lines = _lines(data)
    if len(lines) < 2:
        return None
    i = rng.randrange(len(lines))
    desc = "delete line %d (%r)" % (i + 1, lines[i][:60])
    del lines[i]
    return _join(lines), "delete_line", desc


def m_duplicate_line(data, fmt, rng):
    lines = _lines(data)
    i = rng.randrange(len(lines))
    lines.insert(i, lines[i])
    return _join(lines), "duplicate_line", "duplicate line %d (%r)" % (i + 1, lines[i][:60])


def m_swap_lines(data, fmt, rng):
    lines = _lines(data)
    if len(lines) < 3:
        return None
    i = rng.randrange(len(lines))
    j = min(len(lines) - 1, i + 1) if rng.random() < 0.6 else rng.randrange(len(lines))
    lines[i], lines[j] = lines[j], lines[i]
    return _join(lines), "swap_lines", "swap lines %d and %d" % (i + 1, j + 1)


def _keys(data, fmt):
    if fmt in ("yaml", "opencv"):
        return [(m.start(2), m.end(2), m.group(2)) for m in YAML_KEY.finditer(data)]
    if fmt in ("json", "journal"):
        return [(m.start(1), m.end(1), m.group(1)) for m in JSON_KEY.finditer(data)]
    if fmt == "xml":
        return [(m.start(2), m.end(2), m.group(2)) for m in XML_NAME.finditer(data)] + \
               [(m.start(1), m.end(1), m.group(1)) for m in XML_ATTR.finditer(data)]
    return []


def m_duplicate_key(data, fmt, rng):
    if fmt in ("json", "journal"):
        pairs = list(re.finditer(rb"\"[A-Za-z_]\w*\"\s*:\s*(-?[\d.eE+-]+|\"[^\"]*\"|true|false|null)", data))
        if not pairs:
            return None
        m = pairs[rng.randrange(len(pairs))]
        value = m.group(0)
        if rng.random() < 0.5:
            value = NUMBER.sub(b"7", value, count=1) if NUMBER.search(m.group(1)) else value
        return data[:m.end()] + b", " + value + data[m.end():], "duplicate_key", "duplicate key %r" % m.group(0)[:50]
    lines = _lines(data)
    keyed = [i for i, line in enumerate(lines) if re.match(rb"^\s*[A-Za-z_]\w*\s*:", line)]
    if fmt == "xml" or not keyed:
        return m_duplicate_line(data, fmt, rng)
    i = keyed[rng.randrange(len(keyed))]
    copy = lines[i]
    if rng.random() < 0.5:
        copy = NUMBER.sub(b"7", copy, count=1)
    lines.insert(i + 1, copy)
    return _join(lines), "duplicate_key", "duplicate key line %d (%r)" % (i + 1, copy[:60])


def m_rename_key(data, fmt, rng):
    keys = _keys(data, fmt)
    if not keys:
        return None
    start, end, key = keys[rng.randrange(len(keys))]
    how = rng.randrange(5)
    new = None
    if how == 0:
        for a, b in UNIT_SWAPS:
            if key.endswith(a.rstrip(b"\"")):
                new = key[: len(key) - len(a.rstrip(b"\""))] + b.rstrip(b"\"")
                break
    if new is None and how <= 1 and len(key) > 2:
        i = rng.randrange(len(key) - 1)
        new = key[:i] + key[i + 1:i + 2] + key[i:i + 1] + key[i + 2:]
    if new is None and how == 2:
        new = key.upper()
    if new is None and how == 3:
        new = key + b"s"
    if new is None or new == key:
        i = rng.randrange(len(key))
        new = key[:i] + key[i + 1:]
    if not new:
        new = b"x"
    return data[:start] + new + data[end:], "rename_key", "rename key %r -> %r" % (key, new)


def m_change_value(data, fmt, rng):
    m = _pick_number(data, rng)
    if not m:
        return None
    name, value = rng.choice(_value_replacements(fmt, m.group(0)))
    return data[:m.start()] + value + data[m.end():], "value:" + name, "value %r -> %r (%s)" % (m.group(0), value, name)


def m_change_string(data, fmt, rng):
    strings = list(re.finditer(rb"(?<=: )\"?([A-Za-z][\w .,:/+-]*)\"?(?=\s*(,|\}|\n|$))", data)) if fmt != "xml" else \
        list(re.finditer(rb">([A-Za-z][^<]*)<", data))
    if not strings:
        return None
    m = strings[rng.randrange(len(strings))]
    value = rng.choice([b"", b"x", b"\"\"", m.group(1)[::-1], m.group(1) + m.group(1), b"\xc3\x28", b"../../etc/passwd"])
    return data[:m.start(1)] + value + data[m.end(1):], "string", "string %r -> %r" % (m.group(1)[:40], value)


def m_truncate(data, fmt, rng):
    if not data:
        return None
    i = rng.randrange(len(data))
    return data[:i], "truncate", "truncate at byte %d of %d" % (i, len(data))


def m_empty(data, fmt, rng):
    return rng.choice([b"", b"\n", b" ", b"\x00"]), "empty", "empty file"


def m_garbage(data, fmt, rng):
    i = rng.randrange(len(data) + 1)
    junk = bytes(rng.randrange(256) for _ in range(rng.choice([1, 4, 64, 512])))
    return data[:i] + junk + data[i:], "garbage", "%d random bytes at %d" % (len(junk), i)


def m_flip_byte(data, fmt, rng):
    if not data:
        return None
    i = rng.randrange(len(data))
    b = bytes([data[i] ^ (1 << rng.randrange(8))])
    return data[:i] + b + data[i + 1:], "flip_byte", "flip a bit of byte %d" % i


def m_invalid_utf8(data, fmt, rng):
    i = rng.randrange(len(data) + 1)
    seq = rng.choice([b"\xff", b"\xc3\x28", b"\xe2\x82", b"\xed\xa0\x80", b"\xf8\x88\x80\x80\x80", b"\xc0\xaf"])
    return data[:i] + seq + data[i:], "invalid_utf8", "invalid UTF-8 %r at %d" % (seq, i)


def m_bom(data, fmt, rng):
    bom = rng.choice([b"\xef\xbb\xbf", b"\xef\xbb\xbf", b"\xff\xfe", b"\xfe\xff"])
    op = "bom" if bom == b"\xef\xbb\xbf" else "bom_utf16"
    return bom + data, op, "byte order mark %r" % bom


def m_crlf(data, fmt, rng):
    return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n"), "crlf", "CRLF line ends"


def m_cr_only(data, fmt, rng):
    return data.replace(b"\n", b"\r"), "cr_only", "CR-only line ends"


def m_nul(data, fmt, rng):
    i = rng.randrange(len(data) + 1)
    return data[:i] + b"\x00" + data[i:], "nul", "NUL byte at %d" % i


def m_trailing_space(data, fmt, rng):
    lines = _lines(data)
    i = rng.randrange(len(lines))
    if not lines[i].strip():
        return None
    lines[i] = lines[i] + rng.choice([b" ", b"  ", b"\t", b"   "])
    return _join(lines), "trailing_space", "trailing white space on line %d" % (i + 1)


def m_comment(data, fmt, rng):
    text = _comment(fmt)
    if text is None:
        return None
    lines = _lines(data)
    start = 1 if fmt == "opencv" or (fmt == "xml" and lines and lines[0].startswith(b"<?xml")) else 0
    if len(lines) <= start:
        return None
    i = rng.randrange(start, len(lines) + 1)
    indent = re.match(rb"\s*", lines[i] if i < len(lines) else b"").group(0)
    lines.insert(i, indent + text)
    return _join(lines), "comment", "comment line before line %d" % (i + 1)


def m_respell_number(data, fmt, rng):
    floats = [m for m in NUMBER.finditer(data) if b"." in m.group(0) and b"e" not in m.group(0).lower()]
    if not floats:
        return None
    m = floats[rng.randrange(len(floats))]
    s = m.group(0)
    new = rng.choice([s + b"0", s + b"00", ("%.17g" % float(s)).encode() if "%.17g" % float(s) != s.decode() else s + b"0",
                      ("%.17e" % float(s)).encode()])
    try:
        if float(new) != float(s):
            new = s + b"0"
    except ValueError:
        new = s + b"0"
    return data[:m.start()] + new + data[m.end():], "respell_number", "number %r spelt %r" % (s, new)


def m_deep_nesting(data, fmt, rng):
    depth = rng.choice([100, 1000, 10000, 100000])
    if fmt == "xml":
        close = data.rfind(b"</")
        close = close if close >= 0 else len(data)
        inner = b"<a>" * depth + b"</a>" * depth
        return data[:close] + inner + data[close:], "deep_nesting", "%d nested elements" % depth
    if fmt in ("json", "journal"):
        close = data.rfind(b"}")
        close = close if close >= 0 else len(data)
        return data[:close] + b", \"deep\": " + b"[" * depth + b"]" * depth + data[close:], "deep_nesting", \
            "%d nested arrays" % depth
    lines = _lines(data)
    keyed = [i for i, line in enumerate(lines) if re.match(rb"^\s*[A-Za-z_]\w*\s*:\s*\S", line)]
    if not keyed:
        return data + b"\nx: " + b"[" * depth + b"]" * depth + b"\n", "deep_nesting", "%d nested flow lists" % depth
    i = keyed[rng.randrange(len(keyed))]
    head = re.match(rb"^(\s*[A-Za-z_]\w*\s*:\s*)", lines[i]).group(1)
    lines[i] = head + b"[" * depth + b"]" * depth
    return _join(lines), "deep_nesting", "value of line %d is %d nested flow lists" % (i + 1, depth)


def m_huge(data, fmt, rng):
    lines = _lines(data)
    size = rng.choice([1 << 20, 8 << 20, 40 << 20])
    i = rng.randrange(len(lines))
    line = lines[i] if lines[i].strip() else b"# padding"
    reps = max(1, size // (len(line) + 1))
    lines[i:i + 1] = [line] * reps
    return _join(lines), "huge", "line %d repeated to %d MiB" % (i + 1, size >> 20), line


def m_long_line(data, fmt, rng):
    m = _pick_number(data, rng)
    if not m:
        return None
    return data[:m.start()] + b"1" * rng.choice([400, 100000]) + data[m.end():], "long_number", "a number with many digits"


def m_journal_payload(data, fmt, rng):
    """Change one record's JSON payload and reframe it with a valid length and CRC."""
    lines = _lines(data)
    records = [i for i, line in enumerate(lines) if line.startswith(b"J1 ")]
    if not records:
        return None
    i = records[rng.randrange(len(records))]
    payload = lines[i][21:]
    sub = rng.choice([m_change_value, m_rename_key, m_duplicate_key, m_change_string, m_deep_nesting, m_delete_field])
    res = sub(payload, "json", rng)
    if not res:
        return None
    new, op, desc = res
    lines[i] = b"J1 %08x %08x " % (len(new), zlib.crc32(new) & 0xffffffff) + new
    return _join(lines), "journal:" + op, "record %d (line %d), reframed: %s" % (records.index(i) + 1, i + 1, desc)


def m_delete_field(data, fmt, rng):
    pairs = list(re.finditer(rb",?\s*\"[A-Za-z_]\w*\"\s*:\s*(-?[\d.eE+-]+|\"[^\"]*\"|true|false|null)", data))
    if not pairs:
        return None
    m = pairs[rng.randrange(len(pairs))]
    return data[:m.start()] + data[m.end():], "delete_field", "delete field %r" % m.group(0)[:50]


def m_reorder_json(data, fmt, rng):
    try:
        doc = json.loads(data)
    except ValueError:
        return None
    if not isinstance(doc, dict):
        return None
    items = list(doc.items())
    rng.shuffle(items)
    return json.dumps(dict(items), indent=rng.choice([None, 1, 4])).encode(), "reorder_json", "keys reordered and re-indented"


STRUCTURAL = [m_delete_line, m_duplicate_line, m_swap_lines, m_duplicate_key, m_rename_key, m_change_value,
              m_change_value, m_change_value, m_change_string, m_truncate, m_trailing_space, m_comment,
              m_respell_number, m_deep_nesting]
BYTES = [m_empty, m_garbage, m_flip_byte, m_invalid_utf8, m_bom, m_crlf, m_cr_only, m_nul, m_huge, m_long_line]


def mutate(data, fmt, rng):
    choices = STRUCTURAL * 2 + BYTES
    if fmt == "journal":
        choices = choices + [m_journal_payload] * 12
    if fmt == "json":
        choices = choices + [m_delete_field] * 3 + [m_reorder_json]
    ops = []
    edits = 1 if rng.random() < 0.8 else 2
    for _ in range(20):
        if len(ops) == edits:
            break
        res = rng.choice(choices)(data, fmt, rng)
        if res is None:
            continue
        new, op, desc = res[:3]
        if new == data and op not in PRESERVING:
            continue
        if op == "huge" and any(o["op"] == "huge" for o in ops):
            continue
        data = new
        ops.append({"op": op, "desc": desc, "line": res[3] if len(res) > 3 else None})
    if not ops:
        data, op, desc = m_garbage(data, fmt, rng)
        ops.append({"op": op, "desc": desc})
    return data, ops
