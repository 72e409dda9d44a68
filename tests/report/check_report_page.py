#!/usr/bin/env python3
"""The HTML report in headless Chromium (issue 22). CTest test `report_html_chromium`; exit 77
(CTest: skipped) where Chromium is absent.

1. `quadlod generate vase`, an LOD chain of two `quadlod simplify` runs (the first with
   --report-html), then `quadlod report INPUT LOD1 LOD2 -o report.html`;
2. the page is self-contained: no <script src>, <link href> or url() to fetch, and Chromium runs
   with every host name unresolvable;
3. Chromium loads it (--dump-dom): the viewer records console errors and uncaught exceptions in
   <body data-errors>, and after the first frame counts every view's non-background pixels
   (data-foreground); the test requires no error and every view drawn;
4. Chromium takes a screenshot (--screenshot), which must not be blank; it is kept under
   --screenshot-dir (docs/report.png is a copy).
"""

import argparse
import html.parser
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from png_check import png_summary  # noqa: E402

WINDOW = (1400, 900)


def chromium_binary():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def chromium(binary, profile, *args, timeout=120):
    # As root Chromium needs --no-sandbox; the rest keeps it from reaching the network or
    # updating itself. WebGL without a GPU: SwiftShader, which recent Chromium only allows on request.
    command = [binary, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
               "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--host-resolver-rules=MAP * ~NOTFOUND", f"--user-data-dir={profile}",
               f"--window-size={WINDOW[0]},{WINDOW[1]}", "--hide-scrollbars", "--virtual-time-budget=20000",
               "--enable-logging=stderr", "--v=0", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout)


class BodyAttributes(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.body = None

    def handle_starttag(self, tag, attrs):
        if tag == "body" and self.body is None:
            self.body = dict(attrs)


def run(cli, args, **kw):
    result = subprocess.run([cli, "-q", *args], capture_output=True, text=True, **kw)
    if result.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed ({result.returncode}): {result.stderr}")
    return result


def check_self_contained(page: str, name: str):
    fetches = re.findall(r"<script[^>]*\ssrc=|<link[^>]*\shref=|<img[^>]*\ssrc=|<iframe", page, re.I)
    assert not fetches, f"{name}: the page loads external resources: {fetches[:3]}"
    assert "url(http" not in page, f"{name}: the style fetches a url()"


def check_in_chromium(binary, page: Path, screenshot: Path, fragment=""):
    failures = []
    with tempfile.TemporaryDirectory(prefix="quadlod-chromium-") as profile:
        dom = chromium(binary, profile, "--dump-dom", page.as_uri())
    parser = BodyAttributes()
    parser.feed(dom.stdout)
    body = parser.body or {}
    status = body.get("data-render-status")
    errors = json.loads(body.get("data-errors", "null") or "null")
    foreground = json.loads(body.get("data-foreground", "null") or "null")
    print(f"{page.name}: status {status}, errors {errors}, foreground per view {foreground}")
    logged = [line for line in dom.stderr.splitlines() if "CONSOLE" in line and ("Uncaught" in line or "rror" in line)]
    if status != "ok":
        failures.append(f"{page.name}: render status {status!r} (errors {errors})")
    if errors != []:
        failures.append(f"{page.name}: console errors {errors}")
    if logged:
        failures.append(f"{page.name}: errors in Chromium's console log: {logged[:3]}")
    if not foreground or min(foreground) < 0.02:
        failures.append(f"{page.name}: a view is blank ({foreground})")
    with tempfile.TemporaryDirectory(prefix="quadlod-chromium-") as profile:
        shot = chromium(binary, profile, f"--screenshot={screenshot}", page.as_uri() + fragment)
    if not screenshot.exists():
        failures.append(f"{page.name}: no screenshot ({shot.returncode}): {shot.stderr[-2000:]}")
        return failures
    views_region = (0, 60, WINDOW[0], int(WINDOW[1] * 0.6))  # the canvas, below the header
    summary = png_summary(screenshot, views_region)
    print(f"{screenshot.name}: {summary}")
    if summary["distinct_colours"] < 64 or summary["foreground_fraction"] < 0.05:
        failures.append(f"{screenshot.name}: the canvas looks blank ({summary})")
    return failures


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--cli", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--screenshot-dir", required=True)
    args = parser.parse_args()
    binary = chromium_binary()
    if not binary:
        print("chromium not found (Debian package chromium): skipped")
        return 77
    work = Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    shots = Path(args.screenshot_dir)
    shots.mkdir(parents=True, exist_ok=True)

    vase, lod1, lod2 = work / "vase.obj", work / "vase_LOD1.obj", work / "vase_LOD2.obj"
    single, chain = work / "single.html", work / "report.html"
    run(args.cli, ["generate", "vase", "-o", str(vase)])
    run(args.cli, ["simplify", str(vase), "-o", str(lod1), "--ratio", "0.5", "--report-html", str(single)])
    run(args.cli, ["simplify", str(lod1), "-o", str(lod2), "--ratio", "0.5"])
    run(args.cli, ["report", str(vase), str(lod1), str(lod2), "-o", str(chain), "--samples", "20000"])
    # Refusals: an HTML path that names an input.
    refused = subprocess.run([args.cli, "-q", "report", str(vase), str(lod1), "-o", str(lod1)],
                             capture_output=True, text=True)
    failures = []
    if refused.returncode != 2 or "refusing to overwrite an input" not in refused.stderr:
        failures.append(f"report -o INPUT: exit {refused.returncode}, {refused.stderr.strip()}")

    # The chain's screenshot shows the overlays, the vase standing (report.html#heat,chords,zup):
    # docs/report.png.
    for page, columns, fragment in ((single, 1, ""), (chain, 2, "#heat,chords,zup")):
        text = page.read_text(encoding="utf-8")
        check_self_contained(text, page.name)
        heads = re.search(r'<table id="metrics"><thead><tr>(.*?)</tr>', text).group(1)
        if heads.count("<th>") != columns + 1:
            failures.append(f"{page.name}: {heads.count('<th>') - 1} metric columns, expected {columns}")
        failures += check_in_chromium(binary, page, shots / f"report_{page.stem}.png", fragment)
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
