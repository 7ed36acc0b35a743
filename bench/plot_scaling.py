#!/usr/bin/env python3
"""Draws bench_scaling's CSV as an SVG: frame ms against triangle count on log-log
axes, one panel per thread count, one line per method and Embree mode.
Python 3 standard library only.

    bench/plot_scaling.py [CSV] [-o SVG]      (default docs/scaling-size.csv -> .svg)
"""
import argparse
import csv
import math
import re
import sys
from xml.sax.saxutils import escape

# Families by dash: ray casters dash-dot, 2D pipeline dotted, 3D pipeline solid,
# Embree dashed in black; colours tell the members of a family apart.
STYLE = {
    "rc": ("#7f7f7f", "9 3 2 3"),
    "rc-bvh": ("#d62728", "9 3 2 3"),
    "rc-packet": ("#ff7f0e", "9 3 2 3"),
    "2dr-bb": ("#bcbd22", "2 3"),
    "2dr-bin": ("#17becf", "2 3"),
    "3dr-bb": ("#1f77b4", ""),
    "3dr-bin": ("#2ca02c", ""),
    "3dr-fc": ("#9467bd", ""),
    "3dr-fs": ("#e377c2", ""),
    "3dr-full": ("#8c564b", ""),
    "embree rtcIntersect1": ("#000000", "8 4"),
    "embree rtcIntersect8": ("#000000", "3 3"),
}
SPARE = ["#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173"]  # methods added later
_spare_given = {}

PANEL_W, PANEL_H = 430, 330           # plot area of one panel
LEFT, TOP, GAP, BOTTOM = 70, 70, 60, 60
LEGEND_W = 210
FONT = 'font-family="DejaVu Sans, Arial, sans-serif"'


def read(path):
    """{threads: {method: [(triangles, ms), ...]}}, scene label per triangle count, size,
    and {method: least estimated ms} of the methods skipped wherever they were tried."""
    data, labels, size, skipped = {}, {}, None, {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if not row["frame_ms"]:  # skipped: only an estimate
                est = float(row["estimate_ms"])
                skipped[row["method"]] = min(est, skipped.get(row["method"], est))
                continue
            tris, ms = int(row["triangles"]), float(row["frame_ms"])
            if tris <= 0 or ms <= 0:
                continue  # off a log axis (a frame under the CSV's 1 us resolution)
            data.setdefault(int(row["threads"]), {}).setdefault(row["method"], []).append((tris, ms))
            grid = re.fullmatch(r"grid:.*:(\d+)", row["scene"])
            labels[tris] = grid.group(1) + "²" if grid else row["scene"]
            size = row["size"]
    drawn = {m for lines in data.values() for m in lines}
    return data, labels, size, {m: est for m, est in skipped.items() if m not in drawn}


def span(values):
    """The log10 range an axis shows: the values' own, a little wider."""
    lo, hi = math.log10(min(values)), math.log10(max(values))
    pad = 0.08 * (hi - lo) + 0.1
    return lo - pad, hi + pad


def ticks(rng):
    """The decades inside rng, and the 2..9 multiples of decades inside it."""
    decs = range(math.ceil(rng[0]), math.floor(rng[1]) + 1)
    minor = [k * 10.0 ** e for e in range(math.floor(rng[0]), math.ceil(rng[1]))
             for k in range(2, 10) if rng[0] <= math.log10(k * 10.0 ** e) <= rng[1]]
    return decs, minor


def fmt(e):
    """10**e as a short label: 0.1, 1, 10, 1k, 1M."""
    if e >= 6:
        return f"{10 ** (e - 6)}M"
    if e >= 3:
        return f"{10 ** (e - 3)}k"
    return f"{10.0 ** e:g}"


def style(method):
    if method in STYLE:
        return STYLE[method]
    return _spare_given.setdefault(method, (SPARE[len(_spare_given) % len(SPARE)], "5 2"))


def marker(method, x, y, colour):
    if method.startswith("embree"):
        s = 3.5
        return f'<rect x="{x - s:.1f}" y="{y - s:.1f}" width="{2 * s}" height="{2 * s}" fill="{colour}"/>'
    return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3" fill="{colour}"/>'


def panel(out, x0, threads, lines, labels, xr, yr):
    """One panel whose plot area's top left corner is (x0, TOP)."""
    def px(t):
        return x0 + (math.log10(t) - xr[0]) / (xr[1] - xr[0]) * PANEL_W

    def py(ms):
        return TOP + PANEL_H - (math.log10(ms) - yr[0]) / (yr[1] - yr[0]) * PANEL_H

    y1 = TOP + PANEL_H
    (xdec, xminor), (ydec, yminor) = ticks(xr), ticks(yr)
    # Grid: light lines at 2..9 of each decade, darker ones at the decades.
    for v, shade in [(v, "#ececec") for v in xminor] + [(10.0 ** e, "#c8c8c8") for e in xdec]:
        out.append(f'<line x1="{px(v):.1f}" y1="{TOP}" x2="{px(v):.1f}" y2="{y1}" stroke="{shade}"/>')
    for v, shade in [(v, "#ececec") for v in yminor] + [(10.0 ** e, "#c8c8c8") for e in ydec]:
        out.append(f'<line x1="{x0}" y1="{py(v):.1f}" x2="{x0 + PANEL_W}" y2="{py(v):.1f}" stroke="{shade}"/>')
    out.append(f'<rect x="{x0}" y="{TOP}" width="{PANEL_W}" height="{PANEL_H}" fill="none" stroke="#444"/>')
    for e in xdec:
        x = px(10.0 ** e)
        out.append(f'<line x1="{x:.1f}" y1="{y1}" x2="{x:.1f}" y2="{y1 + 5}" stroke="#444"/>')
        out.append(f'<text x="{x:.1f}" y="{y1 + 19}" text-anchor="middle" font-size="12">{fmt(e)}</text>')
    for e in ydec:
        y = py(10.0 ** e)
        out.append(f'<line x1="{x0 - 5}" y1="{y:.1f}" x2="{x0}" y2="{y:.1f}" stroke="#444"/>')
        out.append(f'<text x="{x0 - 8}" y="{y + 4:.1f}" text-anchor="end" font-size="12">{fmt(e)}</text>')
    # The scenes, named along the top.
    for tris, label in sorted(labels.items()):
        x = px(tris)
        out.append(f'<line x1="{x:.1f}" y1="{TOP}" x2="{x:.1f}" y2="{TOP + 5}" stroke="#444"/>')
        out.append(f'<text x="{x:.1f}" y="{TOP - 5}" text-anchor="middle" font-size="11" fill="#444">'
                   f'{escape(label)}</text>')
    out.append(f'<text x="{x0 + PANEL_W / 2}" y="{TOP - 24}" text-anchor="middle" font-size="14" '
               f'font-weight="bold">{threads} thread{"s" if threads > 1 else ""}</text>')
    out.append(f'<text x="{x0 + PANEL_W / 2}" y="{y1 + 40}" text-anchor="middle" font-size="12">'
               f'triangles</text>')
    out.append(f'<text transform="translate({x0 - 48},{TOP + PANEL_H / 2}) rotate(-90)" text-anchor="middle" '
               f'font-size="12">frame ms</text>')
    for method, pts in lines.items():
        colour, dash = style(method)
        pts = sorted(pts)
        path = " ".join(f"{px(t):.1f},{py(ms):.1f}" for t, ms in pts)
        width = 2.2 if method.startswith("embree") else 1.8
        dasharray = f' stroke-dasharray="{dash}"' if dash else ""
        out.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="{width}"{dasharray}/>')
        out.extend(marker(method, px(t), py(ms), colour) for t, ms in pts)


def legend(out, x0, methods, skipped):
    out.append(f'<text x="{x0}" y="{TOP + 4}" font-size="13" font-weight="bold">method</text>')
    for i, method in enumerate(methods):
        y = TOP + 24 + 21 * i
        colour, dash = style(method)
        dasharray = f' stroke-dasharray="{dash}"' if dash else ""
        out.append(f'<line x1="{x0}" y1="{y}" x2="{x0 + 34}" y2="{y}" stroke="{colour}" stroke-width="2"'
                   f'{dasharray}/>')
        out.append(marker(method, x0 + 17, y, colour))
        out.append(f'<text x="{x0 + 42}" y="{y + 4}" font-size="12">{escape(method)}</text>')
    for i, (method, est) in enumerate(sorted(skipped.items())):
        y = TOP + 24 + 21 * (len(methods) + i) + 6
        out.append(f'<text x="{x0}" y="{y + 4}" font-size="11" fill="#555">{escape(method)}: not drawn, '
                   f'est. ≥ {est / 1000:.0f} s a frame</text>')


def plot(data, labels, size, skipped):
    counts = sorted(data)
    all_pts = [p for lines in data.values() for pts in lines.values() for p in pts]
    xr, yr = span([t for t, _ in all_pts]), span([ms for _, ms in all_pts])
    order = [m for m in STYLE if any(m in lines for lines in data.values())]
    order += sorted({m for lines in data.values() for m in lines} - set(order))
    width = LEFT + len(counts) * (PANEL_W + GAP) + LEGEND_W
    height = TOP + PANEL_H + BOTTOM
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" {FONT}>',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{LEFT}" y="20" font-size="15" font-weight="bold">Frame time against scene size, '
           f'{escape(size)}×{escape(size)}, teapot grids (log-log)</text>']
    for i, threads in enumerate(counts):
        panel(out, LEFT + i * (PANEL_W + GAP), threads, data[threads], labels, xr, yr)
    legend(out, LEFT + len(counts) * (PANEL_W + GAP) - GAP + 25, order, skipped)
    out.append("</svg>")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="?", default="docs/scaling-size.csv")
    ap.add_argument("-o", "--out", help="the SVG to write (default: the CSV's name with .svg)")
    a = ap.parse_args()
    out = a.out or re.sub(r"\.csv$", "", a.csv) + ".svg"
    try:
        data, labels, size, skipped = read(a.csv)
    except (OSError, KeyError, ValueError) as e:
        sys.exit(f"plot_scaling.py: cannot read {a.csv}: {e}")
    if not data:
        sys.exit(f"plot_scaling.py: no measured frames in {a.csv}")
    with open(out, "w") as f:
        f.write(plot(data, labels, size, skipped))
    print(f"wrote {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
