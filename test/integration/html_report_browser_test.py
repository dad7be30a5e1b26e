#!/usr/bin/python3
"""report.html in headless Chromium (Debian's chromium, chromium-driver and python3-selenium).

Runs the selfcal binary as a user would: `simulate --points` (calibrate writes report.html beside
report.json), `report report.json --out again.html` (the same page, the input left unchanged), and
`study` + `report study.json`. Each page is loaded from its file in headless Chromium: it must finish
rendering every figure (plotly's .main-svg in each plot div, the 3-D view's WebGL canvas), log no console
error, and request nothing but itself and data:/blob: URLs. A full-page screenshot of each is saved in
ARTIFACT_DIR (report.png, study.png), with the pages themselves.

Skips (exit 77) with a message when Chromium, its driver, Selenium or PIL is absent: they are installed by
scripts/install-deps for this test only.

  html_report_browser_test.py SELFCAL_BINARY SOURCE_DIR ARTIFACT_DIR
"""
import base64
import hashlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77
CHROMIUM = "/usr/bin/chromium"
DRIVER = "/usr/bin/chromedriver"


def run(binary, args, cwd):
    p = subprocess.run([binary] + args, cwd=cwd, capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    # WebGL (the 3-D view) through SwiftShader, the software renderer: no GPU on a test machine.
    for arg in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--window-size=1280,1600", "--hide-scrollbars",
                "--no-first-run", "--disable-extensions", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--metrics-recording-only"]:
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    return webdriver.Chrome(service=Service(DRIVER), options=options)


def full_page_screenshot(driver, path):
    """The whole page as one PNG, stitched from viewport tiles: a single capture beyond the viewport wraps
    around past 8192 px (the software renderer's largest texture)."""
    from PIL import Image
    viewport = driver.execute_script("return window.innerHeight")
    width = driver.execute_script("return document.documentElement.clientWidth")
    height = driver.execute_script("return document.documentElement.scrollHeight")
    page = Image.new("RGB", (width, height), "white")
    y = 0
    while y < height:
        driver.execute_script("window.scrollTo(0, arguments[0])", y)
        time.sleep(0.3)
        top = driver.execute_script("return window.scrollY")  # the last tile stops at the bottom
        shot = driver.execute_cdp_cmd("Page.captureScreenshot", {"format": "png"})
        tile = Image.open(io.BytesIO(base64.b64decode(shot["data"]))).convert("RGB")
        if tile.width != width:
            tile = tile.resize((width, round(tile.height * width / tile.width)))
        page.paste(tile.crop((0, y - top, width, min(tile.height, height - top))), (0, y))
        y = top + tile.height
    driver.execute_script("window.scrollTo(0, 0)")
    page.save(path)
    return width, height


def check_page(driver, page, screenshot, expect_figures, failures):
    """Loads `page`, waits for its figures, checks console and network, saves the screenshot."""
    url = "file://" + os.path.abspath(page)
    driver.get_log("browser")
    driver.get_log("performance")
    driver.get(url)
    rendered = None
    deadline = time.time() + 120
    while time.time() < deadline:
        rendered = driver.execute_script("return document.body && document.body.getAttribute('data-plots-rendered')")
        if rendered is not None:
            break
        time.sleep(0.2)
    plots = driver.execute_script(
        "return Array.from(document.querySelectorAll('div.plot')).map(function (d) {"
        "  return {id: d.id, svg: d.querySelectorAll('.main-svg').length, gl: d.querySelectorAll('canvas').length,"
        "          title: (d.querySelector('.gtitle') || {}).textContent || ''}; })")
    name = os.path.basename(page)
    if rendered is None:
        failures.append(f"{name}: the figures did not finish rendering within 120 s")
    elif int(rendered) != len(plots):
        failures.append(f"{name}: {rendered} figures rendered of {len(plots)} plot divs")
    if len(plots) != expect_figures:
        failures.append(f"{name}: {len(plots)} plot divs, expected {expect_figures}")
    for p in plots:
        if p["svg"] == 0:
            failures.append(f"{name}: {p['id']} ({p['title']}) has no plotly .main-svg: not rendered")
    # Console: any error fails; warnings are printed.
    for entry in driver.get_log("browser"):
        line = f"{name}: console {entry['level']}: {entry['message']}"
        print(line)
        if entry["level"] == "SEVERE" or "Content Security Policy" in entry["message"]:
            failures.append(line)
    # Network: the page itself, data: and blob: URLs only.
    requests = set()
    for entry in driver.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        if message["method"] == "Network.requestWillBeSent":
            requests.add(message["params"]["request"]["url"])
    for r in sorted(requests):
        if r != url and not r.startswith(("data:", "blob:", "about:")):
            failures.append(f"{name}: requested {r[:200]}")
    width, height = full_page_screenshot(driver, screenshot)
    print(f"{name}: {len(plots)} figures rendered ({', '.join(p['title'] for p in plots)}); "
          f"{len(requests)} requests (the page, data: URLs); screenshot {screenshot} ({width} x {height} px)")
    return plots


def main():
    binary, source, artifacts = sys.argv[1], sys.argv[2], sys.argv[3]
    missing = [p for p in (CHROMIUM, DRIVER) if not os.access(p, os.X_OK)]
    for module, package in (("selenium", "python3-selenium"), ("PIL", "python3-pil")):
        try:
            __import__(module)
        except ImportError:
            missing.append(package)
    if missing:
        print(f"SKIP: headless Chromium test needs {', '.join(missing)} (scripts/install-deps installs "
              "chromium, chromium-driver, python3-selenium and python3-pil)")
        return SKIP
    os.makedirs(artifacts, exist_ok=True)
    failures = []
    with tempfile.TemporaryDirectory(prefix="selfcal-html-") as tmp:
        sim = os.path.join(tmp, "sim")
        code, out = run(binary, ["simulate", "--points", "--seed", "2", "--out", sim], source)
        report_json, report_html = os.path.join(sim, "report.json"), os.path.join(sim, "report.html")
        if code != 0 or not os.path.exists(report_html):
            print(out)
            print(f"FAIL: simulate exited {code}, report.html {'present' if os.path.exists(report_html) else 'absent'}")
            return 1
        before = (sha256(report_json), os.stat(report_json).st_mtime_ns)
        again = os.path.join(tmp, "again.html")
        code, out = run(binary, ["report", report_json, "--out", again], source)
        if code != 0:
            failures.append(f"report report.json exited {code}: {out[-2000:]}")
        elif sha256(again) != sha256(report_html):
            failures.append("report of report.json differs from calibrate's report.html")
        if (sha256(report_json), os.stat(report_json).st_mtime_ns) != before:
            failures.append("report changed its input report.json")
        study_json, study_html = os.path.join(tmp, "study.json"), os.path.join(tmp, "study.html")
        code, out = run(binary, ["study", "--runs", "2", "--noise-px", "0.2", "--no-opencv", "--no-bound",
                                 "--out", study_json], source)
        if code != 0:
            failures.append(f"study exited {code}: {out[-2000:]}")
        else:
            code, out = run(binary, ["report", study_json, "--out", study_html], source)
            if code != 0:
                failures.append(f"report study.json exited {code}: {out[-2000:]}")
        shutil.copy(report_html, os.path.join(artifacts, "report.html"))
        driver = browser()
        try:
            check_page(driver, report_html, os.path.join(artifacts, "report.png"), 9, failures)
            scene = driver.execute_script("return document.querySelectorAll('#plot-1 canvas').length")
            if scene == 0:
                failures.append("report.html: the 3-D view has no WebGL canvas")
            order = driver.execute_script(
                "var v = document.getElementById('verdict'), p = document.querySelector('div.plot');"
                "return v && p ? (v.compareDocumentPosition(p) & Node.DOCUMENT_POSITION_FOLLOWING) !== 0 : false;")
            if not order:
                failures.append("report.html: the verdict is not before the first figure")
            if os.path.exists(study_html):
                shutil.copy(study_html, os.path.join(artifacts, "study.html"))
                check_page(driver, study_html, os.path.join(artifacts, "study.png"), 1, failures)
        finally:
            driver.quit()
    for f in failures:
        print("FAIL:", f)
    print(f"html report browser: {len(failures)} problem(s)" if failures else
          f"html report browser: 2 pages rendered without console errors or requests; screenshots in {artifacts}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
