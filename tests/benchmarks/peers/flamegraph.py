#!/usr/bin/env python3
"""A flame graph (SVG) from `perf script` output, with no other tool.

  perf record -F 20000 -g -o perf.data -- build/rmhb solve ...
  perf script -i perf.data | tests/benchmarks/peers/flamegraph.py --title "..." > flame.svg

Each sample's call stack (outermost first) adds one to every frame on it; a
frame's width is its share of the samples, children stacked above parents,
siblings sorted by name. Frames narrower than 0.1 % are left out.
"""
import argparse
import html
import re
import sys
from collections import defaultdict


def read_stacks(lines):
    stacks, frames, comm = defaultdict(int), [], None
    for line in lines:
        line = line.rstrip("\n")
        if not line.strip():
            if frames:
                stacks[tuple([comm] + frames[::-1])] += 1
            frames, comm = [], None
            continue
        if not line.startswith((" ", "\t")):
            comm = line.split()[0]
            continue
        m = re.match(r"\s*[0-9a-f]+\s+(.*?)\s+\((.*)\)$", line)
        name = m.group(1) if m else line.strip()
        if name == "[unknown]" and m:
            name = "[" + m.group(2).split("/")[-1] + "]"
        name = re.sub(r"\+0x[0-9a-f]+$", "", name)
        name = re.sub(r"\(.*\)( const)?$", "", name)  # drop argument lists
        frames.append(name)
    if frames:
        stacks[tuple([comm] + frames[::-1])] += 1
    return stacks


def tree(stacks):
    root = {"name": "all", "count": 0, "children": {}}
    for stack, n in stacks.items():
        root["count"] += n
        node = root
        for f in stack:
            node = node["children"].setdefault(f, {"name": f, "count": 0, "children": {}})
            node["count"] += n
    return root


def color(name):
    h = sum(ord(c) for c in name) % 60
    if name.startswith("rmhb::"):
        return "rgb(%d,%d,%d)" % (230, 120 + h, 40)
    if "fftw" in name or "libfftw" in name:
        return "rgb(%d,%d,%d)" % (90, 150 + h, 220)
    if "openblas" in name or name.startswith(("d", "D")) and name.endswith("_"):
        return "rgb(%d,%d,%d)" % (100, 190 + h // 2, 100)
    return "rgb(%d,%d,%d)" % (200, 170 + h // 2, 90)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--title", default="flame graph")
    ap.add_argument("--width", type=int, default=1200)
    args = ap.parse_args()
    root = tree(read_stacks(sys.stdin))
    total = max(root["count"], 1)
    row, width = 17, args.width
    rects, depth_max = [], 0

    def walk(node, x, depth):
        nonlocal depth_max
        w = width * node["count"] / total
        if w < width * 0.001:
            return
        depth_max = max(depth_max, depth)
        rects.append((x, depth, w, node))
        cx = x
        for child in sorted(node["children"].values(), key=lambda c: c["name"]):
            walk(child, cx, depth + 1)
            cx += width * child["count"] / total

    walk(root, 0.0, 0)
    height = (depth_max + 1) * row + 40
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="monospace" font-size="11">'
           % (width, height),
           '<rect width="100%%" height="100%%" fill="white"/><text x="%d" y="16" text-anchor="middle" font-size="14">%s'
           ' (%d samples)</text>' % (width // 2, html.escape(args.title), total)]
    for x, depth, w, node in rects:
        y = height - (depth + 1) * row - 4
        share = 100.0 * node["count"] / total
        label = node["name"]
        chars = int(w / 6.6)
        text = label if len(label) <= chars else (label[: chars - 2] + ".." if chars > 3 else "")
        out.append('<g><title>%s: %d samples (%.1f %%)</title><rect x="%.1f" y="%d" width="%.1f" height="%d" '
                   'fill="%s" stroke="white" stroke-width="0.5"/><text x="%.1f" y="%d">%s</text></g>'
                   % (html.escape(label), node["count"], share, x, y, w, row - 1, color(label), x + 2, y + 12,
                      html.escape(text)))
    out.append("</svg>")
    print("\n".join(out))


if __name__ == "__main__":
    main()
