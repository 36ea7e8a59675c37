#!/usr/bin/env python3
"""Tests of the `geomint report` site (docs/REPORT.md) with Debian's tools, run by ctest.

  site_test.py tidy    GEOMINT SOURCE WORK   every page of the fixture site and of the committed
                                             results' site passes `tidy -errors -quiet`
  site_test.py browser GEOMINT SOURCE WORK   headless Chromium loads every page of the committed
                                             results' site: every <img> and relative link exists,
                                             every table has as many rows as its CSV; screenshots
                                             of the index and one scene page go to WORK

Exit 77 (ctest: skipped) with a message when the tool is missing and we are not root (as root,
scripts/install-deps.sh installs it, so a missing tool is a failure).
"""
import base64
import csv
import fcntl
import json
import html.parser
import os
import shutil
import signal
import subprocess
import sys
import urllib.parse
from pathlib import Path

SKIP = 77
SCREENSHOT_SCENE = "fig1_pendulum"


def need(tool, package):
    path = shutil.which(tool)
    if path:
        return path
    message = f"{tool} is not installed (Debian package '{package}'; scripts/install-deps.sh installs it)"
    if os.geteuid() != 0:
        print(f"SKIP: {message}; run as root: apt-get install -y {package}")
        sys.exit(SKIP)
    sys.exit(f"FAIL: {message}, and we are root: run scripts/install-deps.sh")


def build_site(geomint, results, out):
    if out.exists():
        shutil.rmtree(out)
    subprocess.run([geomint, "report", "--results", str(results), "--out", str(out)], check=True)
    return sorted(out.rglob("*.html"))


def tidy(geomint, source, work):
    tool = need("tidy", "tidy")
    failures = 0
    pages = build_site(geomint, source / "tests" / "report" / "results", work / "fixture_site")
    pages += build_site(geomint, source / "results", work / "site")
    for page in pages:
        run = subprocess.run([tool, "-errors", "-quiet", str(page)], capture_output=True, text=True)
        # tidy exits 1 for warnings, 2 for errors; -errors prints both, so any output counts.
        report = (run.stdout + run.stderr).strip()
        if run.returncode != 0 or report:
            failures += 1
            print(f"FAIL {page}: tidy exit {run.returncode}\n{report}")
    print(f"tidy: {len(pages) - failures} of {len(pages)} pages valid")
    return 1 if failures else 0


class Page(html.parser.HTMLParser):
    """The images, links and tables (with their body row counts) of a dumped DOM."""

    def __init__(self):
        super().__init__()
        self.images, self.links, self.tables = [], [], []  # tables: [csv, declared, rows]
        self.in_body = False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images.append(a.get("src", ""))
        elif tag == "a" and "href" in a:
            self.links.append(a["href"])
        elif tag == "table":
            self.tables.append([a.get("data-csv"), a.get("data-rows"), 0])
        elif tag == "tbody":
            self.in_body = True
        elif tag == "tr" and self.in_body and self.tables:
            self.tables[-1][2] += 1

    def handle_endtag(self, tag):
        if tag == "tbody":
            self.in_body = False


def csv_rows(path):
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    return len(list(csv.reader(lines))) - 1  # less the header


class Chromium:
    """One headless Chromium driven over --remote-debugging-pipe (the DevTools protocol as
    NUL-terminated JSON on fds 3 and 4): a start costs ~6 s of CPU here, so every page loads in
    the same browser instead of one `chromium --dump-dom` each."""

    def __init__(self, chromium, profile):
        to_browser_r, self.to_browser = os.pipe()
        self.from_browser, from_browser_w = os.pipe()

        def fds_3_and_4():
            high_r = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
            high_w = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
            os.dup2(high_r, 3)
            os.dup2(high_w, 4)

        self.process = subprocess.Popen(
            [chromium, "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
             "--no-first-run", f"--user-data-dir={profile}", "--remote-debugging-pipe",
             "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=fds_3_and_4, pass_fds=(3, 4))
        os.close(to_browser_r)
        os.close(from_browser_w)
        self.buffer, self.events, self.next_id = b"", [], 0
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget",
                                 {"targetId": target, "flatten": True})["sessionId"]
        self.call("Page.enable", {}, self.session)

    def message(self):
        while b"\0" not in self.buffer:
            chunk = os.read(self.from_browser, 1 << 16)
            if not chunk:
                raise RuntimeError("chromium closed the DevTools pipe")
            self.buffer += chunk
        text, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(text)

    def call(self, method, params, session=None):
        self.next_id += 1
        request = {"id": self.next_id, "method": method, "params": params}
        if session:
            request["sessionId"] = session
        os.write(self.to_browser, json.dumps(request).encode() + b"\0")
        while True:
            reply = self.message()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def load(self, url):
        """Navigates and waits for the load event (images included); returns the DOM."""
        self.events = [e for e in self.events if e.get("method") != "Page.loadEventFired"]
        self.call("Page.navigate", {"url": url}, self.session)
        while not any(e.get("method") == "Page.loadEventFired" for e in self.events):
            self.events.append(self.message())
        self.events.clear()
        return self.call("Runtime.evaluate",
                         {"expression": "document.documentElement.outerHTML",
                          "returnByValue": True}, self.session)["result"]["value"]

    def screenshot(self, url, path):
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": 1280, "height": 1600, "deviceScaleFactor": 1, "mobile": False},
                  self.session)
        self.load(url)
        data = self.call("Page.captureScreenshot", {"format": "png"}, self.session)["data"]
        path.write_bytes(base64.b64decode(data))

    def close(self):
        try:
            self.call("Browser.close", {})
        except (RuntimeError, OSError):
            pass
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def browser(geomint, source, work):
    chromium = need("chromium", "chromium")
    site = work / "site"
    pages = build_site(geomint, source / "results", site)
    problems = []
    tables = 0
    signal.alarm(300)  # the hang guard: a browser that stops answering fails the test
    browser = Chromium(chromium, work / "chromium-profile")
    try:
        for page in pages:
            dom = Page()
            dom.feed(browser.load(page.as_uri()))
            for src in dom.images:
                if not (page.parent / urllib.parse.unquote(src)).is_file():
                    problems.append(f"{page}: <img src='{src}'> does not exist")
            for href in dom.links:
                target = urllib.parse.urlsplit(href)
                if target.scheme or not target.path:
                    continue  # another site, or an anchor on this page
                if not (page.parent / urllib.parse.unquote(target.path)).exists():
                    problems.append(f"{page}: link '{href}' leads nowhere")
            for name, declared, rows in dom.tables:
                if name is None:
                    continue  # the index's table of scenes
                tables += 1
                expected = csv_rows(page.parent / name)
                if rows != expected:
                    problems.append(
                        f"{page}: table {name} shows {rows} rows, the CSV has {expected}")
        for name, page in [("index", site / "index.html"),
                           ("scene", site / SCREENSHOT_SCENE / "index.html")]:
            shot = work / f"screenshot_{name}.png"
            shot.unlink(missing_ok=True)
            browser.screenshot(page.as_uri(), shot)
            if not shot.is_file() or shot.stat().st_size < 10000:
                problems.append(f"no screenshot of {page} at {shot}")
            else:
                print(f"screenshot: {shot}")
    finally:
        browser.close()
    for problem in problems:
        print("FAIL", problem)
    print(f"browser: {len(pages)} pages, {tables} tables checked, {len(problems)} problem(s)")
    return 1 if problems else 0


def main():
    if len(sys.argv) != 5 or sys.argv[1] not in ("tidy", "browser"):
        sys.exit(__doc__)
    geomint, source, work = sys.argv[2], Path(sys.argv[3]), Path(sys.argv[4])
    work.mkdir(parents=True, exist_ok=True)
    return (tidy if sys.argv[1] == "tidy" else browser)(geomint, source, work)


if __name__ == "__main__":
    sys.exit(main())
