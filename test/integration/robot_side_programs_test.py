#!/usr/bin/python3
"""Static checks of the robot-side servers in scripts/robot-side/ (ABB RAPID, KUKA KRL with EthernetKRL).

  /usr/bin/python3 test/integration/robot_side_programs_test.py SOURCE_DIR

No controller runs here: this checks what can be checked from the text. For each program: every request
of the line protocol (docs/robot-protocol.md) is handled, the "send HELLO first" and "busy" refusals are
there, every ERR code used is one of the protocol's. RAPID: no string literal over 80 characters, blocks
balanced. KRL: blocks balanced, every EKI_* call names the channel of the XML. The XML parses and declares
the controller as a TCP server on the port its README states. Exit 0 on pass; else 1, with file:line.
"""
import os
import re
import sys
import xml.etree.ElementTree as ET

REQUESTS = ("HELLO", "LIMITS", "JOINTS", "MOVE", "STATUS", "STOP", "BYE")
ERR_CODES = {"rejected", "protective_stop", "emergency_stop", "bad_request", "fault"}

failures = []


def fail(path, line, text):
    failures.append("%s:%d: %s" % (path, line, text))


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def strip_comments(text, marker):
    """Lines with comments removed (outside string literals); keeps the line count."""
    out = []
    for line in text.split("\n"):
        in_str, cut = False, len(line)
        for i, ch in enumerate(line):
            if ch == '"':
                in_str = not in_str
            elif ch == marker and not in_str:
                cut = i
                break
        out.append(line[:cut])
    return out


def literals(lines):
    """(line number, literal text) for every double-quoted literal; RAPID's "" inside a literal is one quote."""
    for n, line in enumerate(lines, 1):
        for m in re.finditer(r'"((?:[^"]|"")*)"', line):
            yield n, m.group(1)


def check_requests(path, lines, quote_words):
    """Every request word appears as a literal compared against, and the two refusals are present."""
    text = "\n".join(lines)
    for word in REQUESTS:
        if not re.search(r'"%s"' % word, text):
            fail(path, 1, "the request %s is not handled (no \"%s\" literal)" % (word, word))
    if "ERR bad_request send HELLO first" not in text:
        fail(path, 1, "the refusal `ERR bad_request send HELLO first` is missing")
    for n, lit in literals(lines):
        for m in re.finditer(r"\bERR (\S+)", lit):
            code = m.group(1)
            if code not in ERR_CODES:
                fail(path, n, "ERR code %r is not one of the protocol's %s" % (code, sorted(ERR_CODES)))
        if lit.startswith("ERR") and not re.match(r"ERR \S", lit) and lit.strip() != "ERR":
            fail(path, n, "malformed ERR literal %r" % lit)
    # A literal "ERR " followed by a code built at run time (RAPID: "ERR " + scLatched) is checked at
    # the place the code is set: every "..._stop"/"fault" state name used must be a protocol code.


def check_balance(path, lines, pairs):
    """pairs: (opening regex, closing word, name). Counts per file, reports the first excess close."""
    for opening, closing, name in pairs:
        depth, first_open = 0, None
        for n, line in enumerate(lines, 1):
            code = re.sub(r'"(?:[^"]|"")*"', '""', line)
            opens = len(re.findall(opening, code, flags=re.IGNORECASE))
            closes = len(re.findall(r"\b%s\b" % closing, code, flags=re.IGNORECASE))
            if opens and first_open is None:
                first_open = n
            depth += opens - closes
            if depth < 0:
                fail(path, n, "%s closed more often than opened" % closing)
                depth = 0
        if depth > 0:
            fail(path, first_open or 1, "%d %s block(s) not closed by %s" % (depth, name, closing))


def check_rapid(path):
    lines = strip_comments(read(path), "!")
    check_requests(path, lines, True)
    for n, lit in literals(lines):
        # RAPID counts a character escape \hh as one character and "" as one quote.
        length = len(re.sub(r"\\[0-9A-Fa-f]{2}", "x", lit).replace('""', '"').replace("\\\\", "\\"))
        if length > 80:
            fail(path, n, "string literal of %d characters (RAPID strings hold at most 80)" % length)
    check_balance(path, lines, [
        (r"^\s*MODULE\b", "ENDMODULE", "MODULE"),
        (r"^\s*(?:LOCAL\s+)?PROC\b", "ENDPROC", "PROC"),
        (r"^\s*(?:LOCAL\s+)?FUNC\b", "ENDFUNC", "FUNC"),
        (r"^\s*(?:LOCAL\s+)?TRAP\b", "ENDTRAP", "TRAP"),
        (r"^\s*IF\b.*\bTHEN\s*$", "ENDIF", "IF"),
        (r"^\s*WHILE\b", "ENDWHILE", "WHILE"),
        (r"^\s*FOR\b", "ENDFOR", "FOR"),
        (r"^\s*TEST\b", "ENDTEST", "TEST"),
    ])
    for n, line in enumerate(lines, 1):
        if re.match(r"^\s*IF\b", line) and not re.search(r"\bTHEN\s*$", line):
            fail(path, n, "compact IF (no THEN at the end of the line): write IF ... THEN ... ENDIF")


def check_krl(path, channel):
    lines = strip_comments(read(path), ";")
    check_requests(path, lines, True)
    check_balance(path, lines, [
        (r"^\s*(?:GLOBAL\s+)?DEF\b", "END", "DEF"),
        (r"^\s*(?:GLOBAL\s+)?DEFFCT\b", "ENDFCT", "DEFFCT"),
        (r"^\s*IF\b", "ENDIF", "IF"),
        (r"^\s*WHILE\b", "ENDWHILE", "WHILE"),
        (r"^\s*SWITCH\b", "ENDSWITCH", "SWITCH"),
        (r"^\s*LOOP\b", "ENDLOOP", "LOOP"),
        (r"^\s*FOR\b", "ENDFOR", "FOR"),
    ])
    calls = 0
    for n, line in enumerate(lines, 1):
        for m in re.finditer(r"\bEKI_\w+\s*\(\s*([^,)]*)", line, flags=re.IGNORECASE):
            calls += 1
            arg = m.group(1).strip()
            if arg != '"%s"' % channel:
                fail(path, n, "EKI call names %s, not the channel \"%s\" of the XML" % (arg or "nothing", channel))
    if calls == 0:
        fail(path, 1, "no EKI_* call at all")
    raw = read(path)
    if "busy" not in raw:
        fail(path, 1, "the one-client rule (a second client is refused, `busy`) is not addressed")
    for word in ("BRAKE", "RESUME"):
        if not re.search(r"^\s*%s\b" % word, "\n".join(lines), flags=re.MULTILINE):
            fail(path, 1, "no %s: a STOP during a motion is not served" % word)


def readme_port(path):
    m = re.search(r"\bTCP port\D{0,20}?(\d{3,5})", read(path), flags=re.IGNORECASE)
    return int(m.group(1)) if m else None


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    base = os.path.join(sys.argv[1], "scripts", "robot-side")
    abb, kuka = os.path.join(base, "abb"), os.path.join(base, "kuka")
    files = [os.path.join(abb, f) for f in ("SelfcalServer.mod", "SelfcalMotion.mod", "README.md")] + \
            [os.path.join(kuka, f) for f in ("SelfcalServer.xml", "selfcal_server.src", "selfcal_server.dat",
                                             "README.md")]
    missing = [f for f in files if not os.path.isfile(f)]
    for f in missing:
        fail(f, 0, "missing")
    if missing:
        print("\n".join(failures))
        return 1
    for f in files:
        count = read(f).count("\n")
        if count >= 600:
            fail(f, count, "over 600 lines")

    # ABB: the server answers the protocol; the motion module is checked for RAPID's rules.
    server = os.path.join(abb, "SelfcalServer.mod")
    check_rapid(server)
    motion = os.path.join(abb, "SelfcalMotion.mod")
    mlines = strip_comments(read(motion), "!")
    for n, lit in literals(mlines):
        if len(lit) > 80:
            fail(motion, n, "string literal of %d characters (RAPID strings hold at most 80)" % len(lit))
    check_balance(motion, mlines, [
        (r"^\s*MODULE\b", "ENDMODULE", "MODULE"), (r"^\s*(?:LOCAL\s+)?PROC\b", "ENDPROC", "PROC"),
        (r"^\s*(?:LOCAL\s+)?TRAP\b", "ENDTRAP", "TRAP"), (r"^\s*IF\b.*\bTHEN\s*$", "ENDIF", "IF"),
        (r"^\s*WHILE\b", "ENDWHILE", "WHILE"), (r"^\s*(?:LOCAL\s+)?FUNC\b", "ENDFUNC", "FUNC"),
        (r"^\s*TEST\b", "ENDTEST", "TEST")])
    server_text = read(server)
    if "ERR fault busy" not in "\n".join(strip_comments(server_text, "!")):
        fail(server, 1, "a second client is not refused with `ERR fault busy ...`")
    for state in re.findall(r'sc_latch\s+"(\w+)"', server_text):
        if state not in ERR_CODES:
            fail(server, 1, "latched state %r is not one of the protocol's codes" % state)
    for name in ("StopMove", "ClearPath", "MoveAbsJ", "IPers"):
        if name not in read(motion):
            fail(motion, 1, "%s is missing: moves and stops are not carried out" % name)
    # Every PERS shared between the two tasks is declared identically in both.
    pers = lambda t: {m.group(2): m.group(0) for m in re.finditer(r"PERS (\w+) (sc\w+) :=[^;]*;", t)}
    sp, mp = pers(server_text), pers(read(motion))
    for name in sorted(set(sp) & set(mp)):
        if sp[name] != mp[name]:
            fail(motion, 1, "PERS %s declared differently in the two modules" % name)
    for name in ("scCmdSeq", "scDoneSeq", "scStopSeq", "scTarget"):
        if name not in sp or name not in mp:
            fail(motion, 1, "PERS %s is not shared by both modules" % name)
    abb_port = readme_port(os.path.join(abb, "README.md"))
    m = re.search(r"CONST num SC_PORT := (\d+);", server_text)
    if not m or abb_port != int(m.group(1)):
        fail(server, 1, "SC_PORT (%s) differs from the port README.md states (%s)" % (m and m.group(1), abb_port))

    # KUKA: the XML channel, then the KRL.
    xml_path = os.path.join(kuka, "SelfcalServer.xml")
    channel = os.path.splitext(os.path.basename(xml_path))[0]
    try:
        root = ET.parse(xml_path).getroot()
    except ET.ParseError as e:
        fail(xml_path, e.position[0], "does not parse: %s" % e)
        root = None
    if root is not None:
        get = lambda p: (root.findtext(p) or "").strip()
        if root.tag != "ETHERNETKRL":
            fail(xml_path, 1, "the root element is %s, not ETHERNETKRL" % root.tag)
        if get("CONFIGURATION/EXTERNAL/TYPE").lower() != "client":
            fail(xml_path, 1, "EXTERNAL/TYPE must be Client (the external system is the client, the robot the server)")
        if get("CONFIGURATION/INTERNAL/PROTOCOL").upper() != "TCP":
            fail(xml_path, 1, "INTERNAL/PROTOCOL must be TCP")
        port = get("CONFIGURATION/INTERNAL/PORT")
        kuka_port = readme_port(os.path.join(kuka, "README.md"))
        if not port.isdigit() or int(port) != kuka_port:
            fail(xml_path, 1, "INTERNAL/PORT %r differs from the port README.md states (%s)" % (port, kuka_port))
        for section in ("RECEIVE", "SEND"):
            el = root.find("%s/RAW/ELEMENT" % section)
            if el is None or el.get("Type") != "STREAM" or el.get("EOS") != "10":
                fail(xml_path, 1, "%s needs a RAW STREAM element ending in LF (EOS=\"10\")" % section)
    check_krl(os.path.join(kuka, "selfcal_server.src"), channel)
    dat = os.path.join(kuka, "selfcal_server.dat")
    check_balance(dat, strip_comments(read(dat), ";"), [(r"^\s*DEFDAT\b", "ENDDAT", "DEFDAT")])

    if failures:
        print("\n".join(failures))
        print("robot_side_programs_test: %d failure(s)" % len(failures))
        return 1
    print("robot_side_programs_test: ABB and KUKA programs pass (%d files)" % len(files))
    return 0


if __name__ == "__main__":
    sys.exit(main())
