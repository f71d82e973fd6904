#!/usr/bin/python3
"""Renders HTML reports in headless Chromium and checks what a person would see.

For each golden report (tests/reports/golden/<name>.html with its .json): the DOM Chromium builds
holds one <tr class="precondition"> per precondition of the JSON, the screenshot is not blank (many
non-white pixels, more than one colour), and Chromium's log shows no console message (the report
has no script, so any message is an error: a blocked request, a parse failure). Exits 77 (ctest's
skip) with a reason when Chromium is missing or cannot start.

usage: browser_check.py GOLDEN_DIR NAME...
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--enable-logging=stderr", "--v=0"]


def chromium(profile, *arguments):
    command = [shutil.which("chromium") or "chromium", *FLAGS, f"--user-data-dir={profile}",
               *arguments]
    return subprocess.run(command, capture_output=True, text=True, timeout=120)


def png_pixels(path):
    """(width, height, rows of RGB(A) bytes) of an 8-bit RGB or RGBA PNG."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    position, idat, width = 8, b"", 0
    while position < len(data):
        length, kind = struct.unpack(">I4s", data[position:position + 8])
        body = data[position + 8:position + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), f"unexpected PNG format {depth}/{colour}"
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        position += 12 + length
    raw, stride, rows, previous = zlib.decompress(idat), width * channels, [], bytearray(width * channels)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, row = line[0], bytearray(line[1:])
        for i in range(stride):
            left = row[i - channels] if i >= channels else 0
            up = previous[i]
            corner = previous[i - channels] if i >= channels else 0
            if kind == 1:
                row[i] = (row[i] + left) & 255
            elif kind == 2:
                row[i] = (row[i] + up) & 255
            elif kind == 3:
                row[i] = (row[i] + (left + up) // 2) & 255
            elif kind == 4:
                estimate = left + up - corner
                pa, pb, pc = abs(estimate - left), abs(estimate - up), abs(estimate - corner)
                row[i] = (row[i] + (left if pa <= pb and pa <= pc else up if pb <= pc else corner)) & 255
        rows.append(row)
        previous = row
    return width, height, channels, rows


def check(golden, name, profile, problems):
    html = os.path.join(golden, name + ".html")
    report = json.load(open(os.path.join(golden, name + ".json")))
    expected = sum(len(step.get("preconditions", [])) for step in report["chosen"]["steps"])
    url = "file://" + os.path.abspath(html)

    dom = chromium(profile, "--dump-dom", url)
    rows = len(re.findall(r'<tr class="precondition"', dom.stdout))
    if rows != expected:
        problems.append(f"{name}: the DOM has {rows} precondition rows, the JSON {expected}")
    console = [line for line in dom.stderr.splitlines() if "CONSOLE" in line or "Uncaught" in line]
    if console:
        problems.append(f"{name}: console messages: {console[:3]}")

    shot = os.path.join(profile, name + ".png")
    chromium(profile, "--window-size=1280,1600", f"--screenshot={shot}", url)
    if not os.path.exists(shot):
        problems.append(f"{name}: no screenshot")
        return
    width, height, channels, pixels = png_pixels(shot)
    colours, ink = set(), 0
    for row in pixels[::8]:
        for x in range(0, width * channels, channels * 8):
            pixel = bytes(row[x:x + 3])
            colours.add(pixel)
            ink += pixel != b"\xff\xff\xff"
    samples = (height // 8 + 1) * (width // 8 + 1)
    if ink < samples // 50 or len(colours) < 8:
        problems.append(f"{name}: the screenshot looks blank ({ink} of {samples} sampled pixels "
                        f"not white, {len(colours)} colours)")
    print(f"{name}: {rows} precondition rows, {len(colours)} colours, "
          f"{100 * ink // samples}% of the page inked")


def main():
    golden, names = sys.argv[1], sys.argv[2:]
    if shutil.which("chromium") is None:
        print("SKIP: chromium is not installed (scripts/install-deps.sh installs it)")
        return 77
    with tempfile.TemporaryDirectory(prefix="spar-chromium-") as profile:
        try:
            probe = chromium(profile, "--dump-dom", "about:blank")
        except (OSError, subprocess.TimeoutExpired) as error:
            print(f"SKIP: chromium cannot start here: {error}")
            return 77
        if probe.returncode != 0 or "<html" not in probe.stdout:
            print(f"SKIP: chromium cannot start here (exit {probe.returncode}): "
                  f"{probe.stderr.strip().splitlines()[-1:]}")
            return 77
        problems = []
        for name in names:
            check(golden, name, profile, problems)
    for problem in problems:
        print("FAIL:", problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
