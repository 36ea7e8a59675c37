#!/usr/bin/env python3
"""Geometric checks of gnuplot SVG figures: every text lies inside the canvas and the provenance
footer overlaps no other text and sits below every text in its columns. Text extents come from
DejaVu Sans's own advance widths (the font the figures name), read from the TTF file, at the size
the PNG sibling draws them.

Usage: figure_layout_check.py [--font FILE.ttf] SVG_OR_FOLDER...  (a folder: every results/*/*.svg
below it). Exit 0 when all pass, 1 listing every failure, 2 on bad input.
"""
import argparse
import pathlib
import re
import struct
import sys
import xml.etree.ElementTree as ET

DEFAULT_FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
FOOTER = re.compile(r"^geomint \S+ \(")
# Glyph box relative to the baseline, in em: DejaVu's capital and descender heights (the line
# box is taller; these are the inked parts, so two stacked lines of text do not count as touching).
ASCENT, DESCENT = 0.73, 0.24
TOLERANCE = 1.0  # px: rounding of gnuplot's positions
# The SVG says font-size N in px; pngcairo draws the same N-pt font at 96 dpi, 4/3 larger, at the
# same positions. The PNG (what the scenes' READMEs show) is the tighter, so text is measured at
# its size.
PNG_TEXT_SCALE = 4 / 3


class Font:
    """Advance widths of a TrueType font, from its cmap (format 4) and hmtx tables."""

    def __init__(self, path):
        data = pathlib.Path(path).read_bytes()
        tables = {}
        count = struct.unpack(">H", data[4:6])[0]
        for i in range(count):
            tag, _, offset, _ = struct.unpack(">4sIII", data[12 + 16 * i : 28 + 16 * i])
            tables[tag.decode()] = offset
        self.units = struct.unpack(">H", data[tables["head"] + 18 : tables["head"] + 20])[0]
        metrics = struct.unpack(">H", data[tables["hhea"] + 34 : tables["hhea"] + 36])[0]
        hmtx = tables["hmtx"]
        self.advances = [struct.unpack(">H", data[hmtx + 4 * i : hmtx + 4 * i + 2])[0]
                         for i in range(metrics)]
        self.glyph = {}
        cmap = tables["cmap"]
        for i in range(struct.unpack(">H", data[cmap + 2 : cmap + 4])[0]):
            platform, encoding, offset = struct.unpack(">HHI", data[cmap + 4 + 8 * i : cmap + 12 + 8 * i])
            sub = cmap + offset
            if platform == 3 and encoding == 1 and struct.unpack(">H", data[sub : sub + 2])[0] == 4:
                self._read_format4(data, sub)
                break

    def _read_format4(self, data, sub):
        segments = struct.unpack(">H", data[sub + 6 : sub + 8])[0] // 2
        ends = sub + 14
        starts = ends + 2 * segments + 2
        deltas = starts + 2 * segments
        ranges = deltas + 2 * segments
        for s in range(segments):
            end, start = (struct.unpack(">H", data[a + 2 * s : a + 2 * s + 2])[0] for a in (ends, starts))
            delta = struct.unpack(">h", data[deltas + 2 * s : deltas + 2 * s + 2])[0]
            range_offset = struct.unpack(">H", data[ranges + 2 * s : ranges + 2 * s + 2])[0]
            for code in range(start, min(end, 0xFFFE) + 1):
                if range_offset == 0:
                    glyph = (code + delta) & 0xFFFF
                else:
                    at = ranges + 2 * s + range_offset + 2 * (code - start)
                    glyph = struct.unpack(">H", data[at : at + 2])[0]
                    glyph = (glyph + delta) & 0xFFFF if glyph else 0
                self.glyph[code] = glyph

    def width(self, text, size):
        total = 0
        for ch in text:
            glyph = self.glyph.get(ord(ch), 0)
            total += self.advances[min(glyph, len(self.advances) - 1)]
        return total * size / self.units


def texts(svg_path, font):
    """Yield (text, x0, x1, y0, y1) for every <text> in a gnuplot SVG, and the canvas size."""
    root = ET.parse(svg_path).getroot()
    width = float(root.get("width"))
    height = float(root.get("height"))
    boxes = []
    ns = "{http://www.w3.org/2000/svg}"

    def walk(node, size, anchor, transform):
        size = float(node.get("font-size", size / PNG_TEXT_SCALE)) * PNG_TEXT_SCALE
        anchor = node.get("text-anchor", anchor)
        transform = node.get("transform", transform) if node.tag == ns + "g" else transform
        if node.tag == ns + "text":
            content = "".join(node.itertext())
            if content.strip():
                boxes.append(box(content, size, anchor, transform or "", font))
            return
        for child in node:
            walk(child, size, anchor, transform)

    walk(root, 10.0, "start", None)
    return width, height, boxes


def box(content, size, anchor, transform, font):
    move = re.search(r"translate\(([-\d.e]+),([-\d.e]+)\)", transform)
    x, y = (float(move.group(1)), float(move.group(2))) if move else (0.0, 0.0)
    rotate = re.search(r"rotate\(([-\d.e]+)\)", transform)
    angle = float(rotate.group(1)) % 360 if rotate else 0.0
    w = font.width(content, size)
    along = {"start": (0.0, w), "middle": (-w / 2, w / 2), "end": (-w, 0.0)}[anchor]
    across = (-ASCENT * size, DESCENT * size)
    if angle == 0:
        return content, x + along[0], x + along[1], y + across[0], y + across[1]
    if angle == 270:  # reads upwards: along the text is -y, "up" of the glyphs is -x
        return content, x + across[0], x + across[1], y - along[1], y - along[0]
    if angle == 90:
        return content, x - across[1], x - across[0], y + along[0], y + along[1]
    raise ValueError(f"text '{content}' rotated by {angle} degrees: only 0, 90 and 270 are checked")


def check(svg_path, font):
    failures = []
    width, height, boxes = texts(svg_path, font)
    for content, x0, x1, y0, y1 in boxes:
        if x0 < -TOLERANCE or x1 > width + TOLERANCE or y0 < -TOLERANCE or y1 > height + TOLERANCE:
            failures.append(f"text '{content}' spans x {x0:.0f}..{x1:.0f}, y {y0:.0f}..{y1:.0f}: "
                            f"outside the {width:.0f} x {height:.0f} canvas")
    footers = [b for b in boxes if FOOTER.match(b[0])]
    for footer in footers:
        _, fx0, fx1, fy0, fy1 = footer
        for other in boxes:
            if FOOTER.match(other[0]):
                continue  # a multiplot draws the footer once per panel, at the same place
            content, x0, x1, y0, y1 = other
            if x1 > fx0 + TOLERANCE and x0 < fx1 - TOLERANCE and y1 > fy0 + TOLERANCE:
                failures.append(f"footer '{footer[0]}' (y {fy0:.0f}..{fy1:.0f}) is not below text "
                                f"'{content}' (x {x0:.0f}..{x1:.0f}, y {y0:.0f}..{y1:.0f}) above it")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--font", default=DEFAULT_FONT)
    parser.add_argument("--require-footer", action="store_true",
                        help="fail a figure that has no provenance footer")
    parser.add_argument("paths", nargs="+")
    args = parser.parse_args()
    if not pathlib.Path(args.font).is_file():
        print(f"figure_layout_check: font file {args.font} not found (install fonts-dejavu-core)",
              file=sys.stderr)
        return 2
    font = Font(args.font)
    svgs = []
    for name in args.paths:
        path = pathlib.Path(name)
        if path.is_dir():
            svgs += sorted(path.glob("results/*/*.svg")) if (path / "results").is_dir() else sorted(path.glob("*.svg"))
        elif path.suffix == ".svg" and path.is_file():
            svgs.append(path)
        else:
            print(f"figure_layout_check: '{name}' is neither an .svg file nor a folder", file=sys.stderr)
            return 2
    if not svgs:
        print("figure_layout_check: no SVG figure found in " + " ".join(args.paths), file=sys.stderr)
        return 2
    failed = 0
    for svg in svgs:
        problems = check(svg, font)
        if args.require_footer:
            _, _, boxes = texts(svg, font)
            if not any(FOOTER.match(b[0]) for b in boxes):
                problems.append("no provenance footer 'geomint <version> (<commit>)'")
        for problem in problems:
            print(f"{svg}: {problem}")
        failed += bool(problems)
    print(f"figure_layout_check: {len(svgs) - failed} of {len(svgs)} figures pass")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
