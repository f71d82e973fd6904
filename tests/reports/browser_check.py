#!/usr/bin/python3
"""Renders HTML reports in headless Chromium and checks what a person would see.

For each golden report (tests/reports/golden/<name>.html with its .json), on a desktop (1280 x 1600)
and on a phone (390 x 844, mobile emulation: the viewport meta applies):
  - the DOM Chromium builds holds one <tr class="precondition"> per precondition of the JSON and one
    <svg class="cell-view"> per view of the work cell;
  - nothing makes the page scroll sideways, and every bound bar (svg.bound-bar), every drawing of
    the cell (svg.cell-view) and the failing step of the plan (li.step.failed) is on screen
    horizontally (tables may scroll inside their own box; these must not need it);
  - the screenshot is not blank (many non-white pixels, more than one colour);
  - Chromium logs no console message and no exception (the report has no script, so any message
    is an error: a blocked request, a parse failure).
Chromium is driven over its DevTools protocol on a pipe (--remote-debugging-pipe: commands on fd
3, replies on fd 4, NUL-separated JSON). Exits 77 (ctest's skip) with a reason when Chromium is
missing or cannot start. SPAR_SCREENSHOTS=DIR keeps the screenshots there.

usage: browser_check.py GOLDEN_DIR NAME...
"""
import base64
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

CHROMIUM = "/usr/lib/chromium/chromium"  # the binary: Debian's /usr/bin/chromium wrapper is a script
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--remote-debugging-pipe"]
SCREENS = {"desktop": {"width": 1280, "height": 1600, "screenWidth": 1280, "screenHeight": 1600,
                       "deviceScaleFactor": 1, "mobile": False},
           "phone": {"width": 390, "height": 844, "screenWidth": 390, "screenHeight": 844,
                     "deviceScaleFactor": 1, "mobile": True}}

# Measured in the page once it has loaded.
PROBE = """JSON.stringify((function () {
  var w = Math.min(window.innerWidth, screen.width), off = [];
  document.querySelectorAll('svg.bound-bar, svg.cell-view, li.step.failed').forEach(function (e) {
    var box = e.getBoundingClientRect();
    if (box.left < -0.5 || box.right > w + 0.5)
      off.push(e.getAttribute('class') + ' at ' + Math.round(box.left) + '..' + Math.round(box.right));
  });
  return {width: w, page: document.documentElement.scrollWidth,
          height: document.documentElement.scrollHeight,
          preconditions: document.querySelectorAll('tr.precondition').length,
          views: document.querySelectorAll('svg.cell-view').length,
          bars: document.querySelectorAll('svg.bound-bar').length, off: off};
})())"""


class Chromium:
    """One headless Chromium, spoken to over the DevTools protocol on a pipe."""

    def __init__(self, profile):
        commands_read, self._commands = os.pipe()
        self._replies, replies_write = os.pipe()

        def on_fds_3_and_4():  # in the child: dup2 onto a new number makes the fd inheritable
            a, b = os.dup(commands_read), os.dup(replies_write)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.process = subprocess.Popen(
            [CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
            preexec_fn=on_fds_3_and_4, close_fds=False, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        os.close(commands_read)
        os.close(replies_write)
        self._buffer, self._id, self.events = b"", 0, []

    def _message(self):
        while b"\0" not in self._buffer:
            chunk = os.read(self._replies, 1 << 16)
            if not chunk:
                raise RuntimeError("chromium closed its DevTools pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method, session=None, **params):
        self._id += 1
        message = {"id": self._id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        os.write(self._commands, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._message()
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, event, session):
        while True:
            for i, message in enumerate(self.events):
                if message.get("method") == event and message.get("sessionId") == session:
                    return self.events.pop(i)
            self.events.append(self._message())

    def close(self):
        try:
            self.send("Browser.close")
        except (RuntimeError, OSError):
            pass
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
        os.close(self._commands)
        os.close(self._replies)

    def page(self, url, screen):
        """Opens `url` in a new tab emulating `screen`; returns (the probe's result, a PNG)."""
        target = self.send("Target.createTarget", url="about:blank")["targetId"]
        session = self.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Page.enable", "Runtime.enable", "Log.enable"):
            self.send(domain, session)
        self.send("Emulation.setDeviceMetricsOverride", session, **screen)
        self.send("Page.navigate", session, url=url)
        self.wait_for("Page.loadEventFired", session)
        probe = json.loads(self.send("Runtime.evaluate", session, expression=PROBE,
                                     returnByValue=True)["result"]["value"])
        shot = self.send("Page.captureScreenshot", session, format="png")
        self.send("Target.closeTarget", targetId=target)
        logged = [m for m in self.events if m.get("sessionId") == session and m.get("method") in
                  ("Log.entryAdded", "Runtime.consoleAPICalled", "Runtime.exceptionThrown")]
        self.events = [m for m in self.events if m.get("sessionId") != session]
        probe["logged"] = [json.dumps(m.get("params"))[:200] for m in logged]
        return probe, base64.b64decode(shot["data"])


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


def blank(png_path):
    """(looks blank, a description): many non-white pixels and more than one colour or not."""
    width, height, channels, pixels = png_pixels(png_path)
    colours, ink = set(), 0
    for row in pixels[::8]:
        for x in range(0, width * channels, channels * 8):
            pixel = bytes(row[x:x + 3])
            colours.add(pixel)
            ink += pixel != b"\xff\xff\xff"
    samples = (height // 8 + 1) * (width // 8 + 1)
    return (ink < samples // 50 or len(colours) < 8,
            f"{len(colours)} colours, {100 * ink // samples}% of the screen inked")


def check(chromium, golden, name, keep, problems):
    report = json.load(open(os.path.join(golden, name + ".json")))
    preconditions = sum(len(step.get("preconditions", [])) for step in report["chosen"]["steps"])
    views = len(report["cell"]["views"]) if "cell" in report else 0
    url = "file://" + os.path.abspath(os.path.join(golden, name + ".html"))
    for screen_name, screen in SCREENS.items():
        where = f"{name} ({screen_name}, {screen['width']} px)"
        probe, png = chromium.page(url, screen)
        if probe["preconditions"] != preconditions:
            problems.append(f"{where}: the DOM has {probe['preconditions']} precondition rows, "
                            f"the JSON {preconditions}")
        if probe["views"] != views:
            problems.append(f"{where}: the DOM has {probe['views']} cell views, the JSON {views}")
        # A page without a viewport meta is laid out 980 px or more wide and shrunk on a phone.
        if probe["width"] != screen["width"]:
            problems.append(f"{where}: laid out {probe['width']} px wide on a screen of "
                            f"{screen['width']} px (is there a viewport meta?)")
        if probe["page"] > screen["width"]:
            problems.append(f"{where}: the page is {probe['page']} px wide, wider than the "
                            f"screen's {screen['width']} px")
        if probe["off"]:
            problems.append(f"{where}: off screen: {probe['off'][:3]}")
        if probe["logged"]:
            problems.append(f"{where}: console messages: {probe['logged'][:3]}")
        shot = os.path.join(keep, f"{name}-{screen_name}.png")
        with open(shot, "wb") as file:
            file.write(png)
        looks_blank, description = blank(shot)
        if looks_blank:
            problems.append(f"{where}: the screenshot looks blank ({description})")
        print(f"{where}: {probe['preconditions']} precondition rows, {probe['views']} cell views, "
              f"{probe['bars']} bars on screen, page {probe['page']} px wide, {description}")


def main():
    golden, names = sys.argv[1], sys.argv[2:]
    if not os.path.exists(CHROMIUM):
        print("SKIP: chromium is not installed (scripts/install-deps.sh installs it)")
        return 77
    keep = os.environ.get("SPAR_SCREENSHOTS")
    with tempfile.TemporaryDirectory(prefix="spar-chromium-") as profile:
        if keep:
            os.makedirs(keep, exist_ok=True)
        chromium = Chromium(profile)
        try:
            chromium.send("Browser.getVersion")
        except (RuntimeError, OSError) as error:
            print(f"SKIP: chromium cannot start here: {error}")
            chromium.process.kill()
            return 77
        problems = []
        try:
            for name in names:
                check(chromium, golden, name, keep or profile, problems)
        finally:
            chromium.close()
    for problem in problems:
        print("FAIL:", problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
