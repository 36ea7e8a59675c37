#!/usr/bin/env python3
"""Tests of the `geomint report` site (docs/REPORT.md) with Debian's tools, run by ctest.

  site_test.py tidy    GEOMINT SOURCE WORK   every page of the fixture site and of the committed
                                             results' site passes `tidy -errors -quiet`
  site_test.py browser GEOMINT SOURCE WORK   headless Chromium loads every page of the committed
                                             results' site: every <img> and relative link exists,
                                             every table has as many rows as its CSV; what the
                                             pages show: no Markdown left as text, every Markdown
                                             table (README.md, table.md) an HTML table with as
                                             many cells, every figure linked to its file and
                                             captioned, every index row a claim with a number;
                                             screenshots of the index and two scene pages
                                             (one scrolled to a narrative table) go to WORK

Exit 77 (ctest: skipped) with a message when the tool is missing and we are not root (as root,
scripts/install-deps.sh installs it, so a missing tool is a failure).
"""
import base64
import csv
import fcntl
import json
import html.parser
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import urllib.parse
import zlib
from pathlib import Path

SKIP = 77
SCREENSHOT_SCENE = "fig1_pendulum"
NARRATIVE_TABLE_SCENE = "rigid_body"  # its README has Markdown tables


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
    """What a dumped DOM shows: its images, links and tables (with their body row and cell
    counts), the text a reader sees outside <code>/<pre>, its figures and the index's claims."""

    HIDDEN = {"code", "pre", "head", "style", "script", "title"}  # text not checked for markup

    def __init__(self):
        super().__init__()
        self.images, self.links, self.tables = [], [], []  # tables: [csv, declared, rows, cells, narrative]
        self.in_body = False
        self.hidden = 0
        self.text = []  # visible text nodes outside code and pre
        self.figures = []  # {"href", "img", "caption"}
        self.claims = []  # index rows: [claim cell text, text of its .measured span]
        self.stack = []  # open tags with their classes, for the narrative and claim cells
        self.figure = self.anchor = None

    def inside(self, tag, cls=None):
        return any(t == tag and (cls is None or cls in c) for t, c in self.stack)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        classes = (a.get("class") or "").split()
        if tag not in ("img", "br", "meta", "link", "input", "hr"):
            self.stack.append((tag, classes))
        if tag in self.HIDDEN:
            self.hidden += 1
        if tag == "img":
            self.images.append(a.get("src", ""))
            if self.figure is not None:
                self.figure["img"] = a.get("src", "")
                self.figure["img_in_link"] = self.anchor is not None
        elif tag == "a" and "href" in a:
            self.links.append(a["href"])
            self.anchor = a["href"]
            if self.figure is not None:
                self.figure["href"] = a["href"]
        elif tag == "figure":
            self.figure = {"href": None, "img": None, "caption": None, "img_in_link": False}
        elif tag == "figcaption" and self.figure is not None:
            self.figure["caption"] = ""
        elif tag == "table":
            self.tables.append([a.get("data-csv"), a.get("data-rows"), 0, 0,
                                self.inside("div", "narrative")])
        elif tag == "tbody":
            self.in_body = True
        elif tag == "tr" and self.in_body and self.tables:
            self.tables[-1][2] += 1
        elif tag in ("td", "th") and self.tables:
            self.tables[-1][3] += 1
            if tag == "td" and "claim" in classes:
                self.claims.append(["", ""])

    def handle_endtag(self, tag):
        if tag == "tbody":
            self.in_body = False
        elif tag == "a":
            self.anchor = None
        elif tag == "figure" and self.figure is not None:
            self.figures.append(self.figure)
            self.figure = None
        if tag in self.HIDDEN:
            self.hidden = max(0, self.hidden - 1)
        for k in range(len(self.stack) - 1, -1, -1):  # close the innermost open tag of that name
            if self.stack[k][0] == tag:
                del self.stack[k:]
                break

    def handle_data(self, data):
        if not self.hidden:
            self.text.append(data)
        if self.figure is not None and self.figure["caption"] is not None \
                and self.inside("figcaption"):
            self.figure["caption"] += data
        if self.claims and self.inside("td", "claim"):
            self.claims[-1][0] += data
            if self.inside("span", "measured"):
                self.claims[-1][1] += data


# Markdown that a renderer left as text: a table's delimiter row or one of its rows, emphasis,
# strong emphasis and code spans. "h*omega" (a product) is not emphasis: the opening * must not
# follow a letter or digit.
RAW_MARKUP = [
    ("a table's delimiter row", re.compile(r"\|\s*:?-{3,}")),
    ("a table row", re.compile(r"^\s*\|[^\n]*\|[^\n]*\|\s*$", re.M)),
    ("emphasis", re.compile(r"(?<![\w*\\])\*{1,2}(?=[^\s*])[^*\n]*?(?<=[^\s*])\*{1,2}(?![\w*])")),
    ("a code span", re.compile(r"`")),
]


def raw_markup(texts):
    """The Markdown left in a page's visible text nodes: [(what, excerpt)]."""
    found = []
    for text in texts:
        for what, pattern in RAW_MARKUP:
            match = pattern.search(text)
            if match:
                found.append((what, text[max(0, match.start() - 30):match.end() + 30].strip()))
    return found


FENCE = re.compile(r"^\s{0,3}(```|~~~)")
DELIMITER_CELL = re.compile(r"^\s*:?-+:?\s*$")
BLOCK_START = re.compile(r"^\s{0,3}(#{1,6}\s|>|[-*+]\s|\d{1,9}[.)]\s)")  # ends a table


def split_cells(line):
    """The cells of a GitHub table line: split at unescaped pipes, outer pipes dropped."""
    line = line.strip()
    if line.startswith("|"):
        line = line[1:]
    if line.endswith("|") and not line.endswith("\\|"):
        line = line[:-1]
    return re.split(r"(?<!\\)\|", line)


def markdown_table_cells(text):
    """The cell count of every GitHub table of a Markdown text, in order: the header's columns
    times its rows (a renderer pads short rows and cuts long ones to the header's width)."""
    lines, tables, fenced, k = text.split("\n"), [], False, 0
    while k < len(lines):
        if FENCE.match(lines[k]):
            fenced = not fenced
            k += 1
            continue
        if fenced or "|" not in lines[k] or k + 1 >= len(lines):
            k += 1
            continue
        header, delimiter = split_cells(lines[k]), split_cells(lines[k + 1])
        if "|" not in lines[k + 1] and "-" not in lines[k + 1] or \
                not all(DELIMITER_CELL.match(c) for c in delimiter) or len(header) != len(delimiter):
            k += 1
            continue
        rows, k = 1, k + 2
        while k < len(lines) and lines[k].strip() and not FENCE.match(lines[k]) \
                and not BLOCK_START.match(lines[k]):
            rows, k = rows + 1, k + 1
        tables.append(len(header) * rows)
    return tables


def png_pixels(path):
    """(width, height, RGB(A) rows) of an 8-bit PNG: chunks, zlib and the five row filters."""
    data = path.read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    at, idat, header = 8, b"", None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f"unexpected PNG format {header}")
    bpp = 3 if colour == 2 else 4
    raw, stride = zlib.decompress(idat), width * bpp
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if kind == 1:
            for i in range(bpp, stride):
                row[i] = (row[i] + row[i - bpp]) & 255
        elif kind == 2:
            row = bytearray((a + b) & 255 for a, b in zip(row, previous))
        elif kind == 3:
            for i in range(stride):
                row[i] = (row[i] + ((row[i - bpp] if i >= bpp else 0) + previous[i]) // 2) & 255
        elif kind == 4:
            for i in range(stride):
                a = row[i - bpp] if i >= bpp else 0
                b, c = previous[i], previous[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[i] = (row[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(row))
        previous = row
    return width, height, bpp, rows


def screenshot_problems(path, width, height):
    """Why a screenshot is not a picture of a page: not a PNG of that size, or (nearly) blank."""
    try:
        w, h, bpp, rows = png_pixels(path)
    except (ValueError, zlib.error, struct.error, TypeError) as error:
        return [f"{path}: does not decode as a PNG ({error})"]
    if (w, h) != (width, height):
        return [f"{path}: {w}x{h} pixels, expected {width}x{height}"]
    colours, background = {}, 0
    for row in rows[::4]:  # every fourth row: enough to tell a page from a blank
        for x in range(0, len(row), bpp * 2):
            pixel = row[x:x + 3]
            colours[pixel] = colours.get(pixel, 0) + 1
    sampled = sum(colours.values())
    background = max(colours.values())
    dark = sum(n for p, n in colours.items() if sum(p) < 3 * 100)  # text and table borders
    if len(colours) < 16 or background > 0.98 * sampled or dark < 0.002 * sampled:
        return [f"{path}: looks blank ({len(colours)} colours, background {background}/{sampled}, "
                f"dark {dark})"]
    return []


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

    def screenshot(self, url, path, scroll_to=None):
        """A 1280x1600 PNG of the page, scrolled first to the element `scroll_to` selects."""
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": 1280, "height": 1600, "deviceScaleFactor": 1, "mobile": False},
                  self.session)
        self.load(url)
        if scroll_to:
            found = self.call("Runtime.evaluate", {
                "expression": f"(e => e ? (e.scrollIntoView(), true) : false)"
                              f"(document.querySelector({json.dumps(scroll_to)}))",
                "returnByValue": True}, self.session)["result"]["value"]
            if not found:
                raise RuntimeError(f"{url}: no element {scroll_to} to show")
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


def figure_problems(page, dom, scene_folder):
    """Every figure links to its full-size file and has a caption that is not its file name; every
    figure of the scene folder is on the page."""
    problems = []
    for figure in dom.figures:
        href, img, caption = figure["href"], figure["img"], (figure["caption"] or "").strip()
        name = img or href or "?"
        if not href or not figure["img_in_link"] or \
                not (page.parent / urllib.parse.unquote(href)).is_file():
            problems.append(f"{page}: figure {name} is not a link to its full-size file ({href})")
        if not caption:
            problems.append(f"{page}: figure {name} has no caption (add it to "
                            f"{scene_folder / 'figures.toml'})")
        elif caption in (name, Path(name).stem, Path(name).name):
            problems.append(f"{page}: figure {name} is captioned with its file name")
    drawn = {p.stem for p in scene_folder.iterdir() if p.suffix in (".png", ".svg")}
    shown = {Path(f["img"] or "").stem for f in dom.figures}
    for stem in sorted(drawn - shown):
        problems.append(f"{page}: figure {stem} of {scene_folder} is not shown")
    return problems


def table_problems(page, dom, markdown_file):
    """Every Markdown table of `markdown_file` is an HTML table of the page's narrative with as
    many cells, in order."""
    expected = markdown_table_cells(markdown_file.read_text())
    shown = [cells for name, _, _, cells, narrative in dom.tables if narrative]
    if expected != shown:
        return [f"{page}: the Markdown tables of {markdown_file} have {expected} cells, the page "
                f"shows tables of {shown} cells"]
    return []


def browser(geomint, source, work):
    chromium = need("chromium", "chromium")
    site = work / "site"
    results = source / "results"
    pages = build_site(geomint, results, site)
    problems = []
    tables = markdown_tables = figures = 0
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
            for name, declared, rows, _, _ in dom.tables:
                if name is None:
                    continue  # the index's table of scenes, or a Markdown table
                tables += 1
                expected = csv_rows(page.parent / name)
                if rows != expected:
                    problems.append(
                        f"{page}: table {name} shows {rows} rows, the CSV has {expected}")
            for what, excerpt in raw_markup(dom.text):
                problems.append(f"{page}: {what} shown as Markdown text: ...{excerpt}...")
            # What each page is made of: a scene's README and figures, table.md, the index.
            scene_folder = results / page.parent.name
            if page.name == "index.html" and page.parent != site:
                if (scene_folder / "README.md").is_file():
                    problems += table_problems(page, dom, scene_folder / "README.md")
                problems += figure_problems(page, dom, scene_folder)
                figures += len(dom.figures)
            elif page.name == "table.html":
                problems += table_problems(page, dom, scene_folder / "table.md")
            markdown_tables += sum(1 for table in dom.tables if table[4])
            if page == site / "index.html":
                scenes = sorted(p.parent.name for p in results.glob("*/scene.toml"))
                if len(dom.claims) != len(scenes):
                    problems.append(f"{page}: {len(dom.claims)} claims for {len(scenes)} scenes")
                for scene, (claim, measured) in zip(scenes, dom.claims):
                    if not re.search(r"\d", measured):
                        problems.append(f"{page}: the claim of {scene} shows no measured number: "
                                        f"{claim.strip()[:200]!r}")
        for scene in sorted(p.parent.name for p in results.glob("*/table.md")):
            if not (site / scene / "table.html").is_file():
                problems.append(f"{results / scene / 'table.md'} is not on the site (table.html)")
        for name, page, scroll_to in [
                ("index", site / "index.html", None),
                ("scene", site / SCREENSHOT_SCENE / "index.html", None),
                ("narrative_table", site / NARRATIVE_TABLE_SCENE / "index.html",
                 ".narrative table")]:
            shot = work / f"screenshot_{name}.png"
            shot.unlink(missing_ok=True)
            try:
                browser.screenshot(page.as_uri(), shot, scroll_to)
            except RuntimeError as error:  # e.g. no narrative table on the page
                problems.append(f"no screenshot of {page}: {error}")
                continue
            if not shot.is_file():
                problems.append(f"no screenshot of {page} at {shot}")
                continue
            found = screenshot_problems(shot, 1280, 1600)
            problems += found
            if not found:
                print(f"screenshot: {shot}")
    finally:
        browser.close()
    for problem in problems:
        print("FAIL", problem)
    print(f"browser: {len(pages)} pages, {tables} tables checked, {markdown_tables} Markdown "
          f"tables, {figures} figures, {len(problems)} problem(s)")
    return 1 if problems else 0


def main():
    if len(sys.argv) != 5 or sys.argv[1] not in ("tidy", "browser"):
        sys.exit(__doc__)
    geomint, source, work = sys.argv[2], Path(sys.argv[3]), Path(sys.argv[4])
    work.mkdir(parents=True, exist_ok=True)
    return (tidy if sys.argv[1] == "tidy" else browser)(geomint, source, work)


if __name__ == "__main__":
    sys.exit(main())
