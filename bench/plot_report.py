#!/usr/bin/python3
"""Plot the vrlcuts benchmark report.

Usage:
    /usr/bin/python3 bench/plot_report.py --results results.csv \
        [--speedup speedup.csv] --out DIR

Writes, for every scene in results.csv, DIR/error-time-<scene>.png: three
log-log panels (RMSE, relative RMSE, SMAPE against wall time in seconds), one
curve per method (or per method and error threshold for the Lightcuts
methods when several thresholds were run). A point of several renders
(columns renders, rmse_min, rmse_max) has a vertical bar on the RMSE panel:
the range of its renders' RMSEs.

If --speedup names a file with at least one usable row, also writes
DIR/speedup.png: the speed-up of Lightcuts over brute force against the
number of virtual lights (log-log), one curve per (scene, kind); solid for
VRL, dashed for VPL.

Uses only the standard library and matplotlib (Agg backend). On Debian 12:
    apt-get install python3-matplotlib
"""

import argparse
import csv
import math
import pathlib
import re
import sys

RESULTS_COLUMNS = [
    "scene", "method", "setting", "vrls", "spp", "error_threshold",
    "seconds", "rmse", "rel_rmse", "smape", "mean_eval", "mean_inter",
    "mean_cut", "mean_ratio", "cut_size", "ref_noise_rmse", "below_noise",
    "part", "renders", "rmse_min", "rmse_max", "distance_samples",
]
SPEEDUP_COLUMNS = [
    "scene", "kind", "n", "brute_seconds_per_pixel",
    "lightcuts_seconds_per_pixel", "speedup", "mean_eval", "mean_inter",
    "rel_rmse",
]

# Columns the plots read: missing one is an error. The other expected
# columns only draw a warning, so that a benchmark writing a few more or
# fewer diagnostic columns does not break the report.
RESULTS_REQUIRED = ["scene", "method", "error_threshold", "seconds", "rmse",
                    "rel_rmse", "smape"]
SPEEDUP_REQUIRED = ["scene", "kind", "n", "speedup"]

METHOD_STYLE = {
    # method: (label, colour, marker)
    "path": ("Path tracing", "#7f7f7f", "s"),
    "vrl": ("VRL (brute force)", "#1f77b4", "o"),
    "vrl-lightcuts": ("VRL Lightcuts", "#d62728", "^"),
    "vpl-lightcuts": ("VPL Lightcuts", "#2ca02c", "v"),
    "vrl-stochastic": ("Stochastic VRL Lightcuts", "#9467bd", "D"),
}
METHOD_ORDER = ["path", "vrl", "vrl-lightcuts", "vrl-stochastic",
                "vpl-lightcuts"]
THRESHOLD_METHODS = ("vrl-lightcuts", "vpl-lightcuts")
# Colours for methods not listed above (stable per method name).
EXTRA_COLOURS = ["#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf",
                 "#ff7f0e"]
EXTRA_MARKERS = ["D", "P", "X", "*", "h", "<", ">"]

ERROR_PANELS = [
    ("rmse", "RMSE"),
    ("rel_rmse", "relative RMSE"),
    ("smape", "SMAPE"),
]


def die(message):
    print("plot_report.py: error: " + message, file=sys.stderr)
    sys.exit(1)


def import_pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        die("cannot import matplotlib (%s). Install it with "
            "'apt-get install python3-matplotlib' and run this script with "
            "the system Python, /usr/bin/python3." % exc)
    return plt


def format_tick(value, _pos=None):
    """Short tick label: plain decimals near 1, mathtext powers otherwise."""
    if value <= 0 or not math.isfinite(value):
        return ""
    if 1e-3 <= value < 1e3:
        return "%g" % float("%.3g" % value)
    exponent = int(math.floor(math.log10(value) + 1e-9))
    mantissa = value / 10.0 ** exponent
    if abs(mantissa - 1.0) < 1e-6:
        return r"$10^{%d}$" % exponent
    return r"$%g\times10^{%d}$" % (float("%.2g" % mantissa), exponent)


def tidy_log_axis(axis, lo, hi):
    """Readable ticks on a log axis: labelled 1-2-5 ticks on short ranges,
    decades on long ones, never labelled minor ticks (they overlap)."""
    from matplotlib import ticker
    if lo > 0 and hi > lo:
        span = math.log10(hi / lo)
    else:
        span = 10.0
    if span < 0.6:
        # Too short for 1-2-5 ticks: a few evenly spaced round values.
        locator = ticker.MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10])
    elif span < 1.0:
        locator = ticker.LogLocator(base=10.0, subs=(1.0, 2.0, 3.0, 5.0))
    elif span < 2.5:
        locator = ticker.LogLocator(base=10.0, subs=(1.0, 2.0, 5.0))
    else:
        locator = ticker.LogLocator(base=10.0, subs=(1.0,))
    axis.set_major_locator(locator)
    axis.set_major_formatter(ticker.FuncFormatter(format_tick))
    axis.set_minor_locator(ticker.LogLocator(base=10.0,
                                             subs=tuple(range(1, 10))))
    axis.set_minor_formatter(ticker.NullFormatter())


def tidy_log_axes(ax):
    tidy_log_axis(ax.xaxis, *ax.get_xlim())
    tidy_log_axis(ax.yaxis, *ax.get_ylim())


def sanitise(name):
    cleaned = re.sub(r"[^A-Za-z0-9_-]", "_", name)
    return cleaned or "scene"


def to_float(text):
    """Parse a float; None when empty or unparsable. nan/inf stay as such."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def positive_finite(value):
    return value is not None and math.isfinite(value) and value > 0


def read_csv(path, required, expected, what):
    path = pathlib.Path(path)
    if not path.is_file():
        die("%s file %s does not exist" % (what, path))
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            reader = csv.DictReader(handle)
            header = [h.strip() for h in (reader.fieldnames or [])]
            if not header:
                die("%s file %s is empty (no header row)" % (what, path))
            missing = [c for c in required if c not in header]
            if missing:
                die("%s file %s lacks required column(s): %s (has: %s)"
                    % (what, path, ", ".join(missing), ", ".join(header)))
            absent = [c for c in expected if c not in header]
            if absent:
                print("warning: %s file %s lacks column(s) %s (not needed "
                      "for the plots)" % (what, path, ", ".join(absent)),
                      file=sys.stderr)
            rows = []
            for raw in reader:
                row = {}
                for key, value in raw.items():
                    if key is None:
                        continue  # surplus fields on a malformed line
                    row[key.strip()] = (value or "").strip()
                rows.append(row)
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        die("cannot read %s file %s: %s" % (what, path, exc))
    return rows


def method_style(method, extra_index):
    if method in METHOD_STYLE:
        return METHOD_STYLE[method]
    i = extra_index.setdefault(method, len(extra_index))
    return (method, EXTRA_COLOURS[i % len(EXTRA_COLOURS)],
            EXTRA_MARKERS[i % len(EXTRA_MARKERS)])


def method_sort_key(method):
    if method in METHOD_ORDER:
        return (METHOD_ORDER.index(method), method)
    return (len(METHOD_ORDER), method)


def format_threshold(text):
    value = to_float(text)
    if value is None:
        return text
    return "%g" % value


def build_curves(rows):
    """Group the rows of one scene into curves.

    Returns a list of (label, colour, marker, linestyle, points) where
    points is a list of row dicts sorted by seconds.
    """
    by_method = {}
    for row in rows:
        by_method.setdefault(row["method"], []).append(row)

    curves = []
    for method in sorted(by_method, key=method_sort_key):
        label, colour, marker = method_style(method, build_curves.extra)
        method_rows = by_method[method]
        groups = [(None, method_rows)]
        if method == "vrl-stochastic":
            sizes = {}
            for row in method_rows:
                sizes.setdefault(row.get("cut_size", ""), []).append(row)
            groups = sorted(sizes.items(),
                            key=lambda item: to_float(item[0]) or 0.0)
        elif method in THRESHOLD_METHODS:
            thresholds = {}
            for row in method_rows:
                key = format_threshold(row["error_threshold"])
                thresholds.setdefault(key, []).append(row)
            if len(thresholds) > 1:
                def threshold_key(item):
                    value = to_float(item[0])
                    return (value is None or not math.isfinite(value),
                            value if value is not None else 0.0, item[0])
                groups = sorted(thresholds.items(), key=threshold_key)
        linestyles = ["-", "--", ":", "-."]
        for index, (threshold, group) in enumerate(groups):
            if threshold is None:
                text = label
            elif method == "vrl-stochastic":
                text = "%s (K=%s)" % (label, threshold)
            else:
                text = "%s (\u03b5=%s)" % (label, threshold)
            style = linestyles[index % len(linestyles)]
            group = sorted(group, key=lambda r: (
                to_float(r["seconds"]) if positive_finite(
                    to_float(r["seconds"])) else math.inf))
            curves.append((text, colour, marker, style, group))
    return curves


build_curves.extra = {}


def plot_scene(plt, scene, rows, out_dir):
    curves = build_curves(rows)
    fig, axes = plt.subplots(1, len(ERROR_PANELS), figsize=(12, 3.8),
                             dpi=110)
    handles = []
    labels = []
    skipped = 0
    for ax, (column, title) in zip(axes, ERROR_PANELS):
        drawn = 0
        for text, colour, marker, style, group in curves:
            xs, ys = [], []
            for row in group:
                x = to_float(row["seconds"])
                y = to_float(row[column])
                if positive_finite(x) and positive_finite(y):
                    xs.append(x)
                    ys.append(y)
                else:
                    skipped += 1
            if not xs:
                continue
            (line,) = ax.plot(xs, ys, color=colour, marker=marker,
                              linestyle=style, linewidth=1.5, markersize=5,
                              label=text)
            if column == "rmse":
                # A point of several renders: the range of their RMSEs (its
                # marker is their root-mean-square).
                for row in group:
                    x = to_float(row["seconds"])
                    low = to_float(row.get("rmse_min"))
                    high = to_float(row.get("rmse_max"))
                    renders = to_float(row.get("renders"))
                    if (renders is not None and renders > 1
                            and positive_finite(x) and positive_finite(low)
                            and positive_finite(high) and high > low):
                        ax.plot([x, x], [low, high], color=colour,
                                linewidth=1.0, alpha=0.8)
            drawn += 1
            if text not in labels:
                labels.append(text)
                handles.append(line)
        # The noise rule's floor: 3x the reference's own RMSE (below it, errors
        # cannot be told from the reference's noise).
        noise = [to_float(r.get("ref_noise_rmse")) for r in rows]
        noise = [v for v in noise if positive_finite(v)]
        if column == "rmse" and noise:
            floor = 3.0 * noise[0]
            line = ax.axhline(floor, color="0.5", linestyle=":",
                              linewidth=1.0,
                              label="3x reference noise (noise rule)")
            if line.get_label() not in labels:
                labels.append(line.get_label())
                handles.append(line)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title)
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel(title)
        if drawn:
            tidy_log_axes(ax)
        else:
            ax.text(0.5, 0.5, "no positive finite data", ha="center",
                    va="center", transform=ax.transAxes, color="0.4")
        ax.grid(True, which="major", alpha=0.5)
        ax.grid(True, which="minor", alpha=0.15)
    if rows and rows[0].get("part") == "multiple":
        fig.suptitle("%s, part (d) alone: error against time" % rows[0]["scene"])
    else:
        fig.suptitle("%s: error against time" % scene)
    bottom = 0.0
    if handles:
        # One shared legend below the panels, so it never hides data.
        ncol = min(len(handles), 4)
        nrows = (len(handles) + ncol - 1) // ncol
        fig.legend(handles, labels, loc="lower center", ncol=ncol,
                   fontsize="small", frameon=False)
        bottom = min(0.015 + 0.055 * nrows, 0.4)
    fig.tight_layout(rect=(0.0, bottom, 1.0, 1.0))
    path = out_dir / ("error-time-%s.png" % sanitise(scene))
    fig.savefig(path)
    plt.close(fig)
    return path, skipped


def plot_speedup(plt, rows, out_dir):
    series = {}
    scenes = []
    skipped = 0
    for row in rows:
        n = to_float(row["n"])
        s = to_float(row["speedup"])
        if not (positive_finite(n) and positive_finite(s)):
            skipped += 1
            continue
        scene = row["scene"]
        if scene not in scenes:
            scenes.append(scene)
        kind = row["kind"].upper()
        series.setdefault((scene, kind), []).append((n, s))
    if not series:
        return None, skipped

    palette = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
               "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]
    kind_style = {"VRL": ("-", "o"), "VPL": ("--", "s"),
                  "VRL-STOCHASTIC": (":", "D")}

    fig, ax = plt.subplots(figsize=(8, 5), dpi=110)
    ax.axhline(1.0, color="black", linewidth=1.0, linestyle=":",
               label="break-even (speed-up 1)")

    def series_key(item):
        scene, kind = item
        return (scenes.index(scene),
                {"VRL": 0, "VRL-STOCHASTIC": 1, "VPL": 2}.get(kind, 3), kind)

    for scene, kind in sorted(series, key=series_key):
        points = sorted(series[(scene, kind)])
        colour = palette[scenes.index(scene) % len(palette)]
        style, marker = kind_style.get(kind, ("-.", "D"))
        ax.plot([p[0] for p in points], [p[1] for p in points],
                color=colour, linestyle=style, marker=marker, markersize=5,
                linewidth=1.5, label="%s (%s)" % (scene, kind))
    ax.set_xscale("log")
    ax.set_yscale("log")
    tidy_log_axes(ax)
    ax.set_xlabel("number of virtual lights n")
    ax.set_ylabel("speed-up (brute force time / Lightcuts time)")
    ax.set_title("Speed-up of Lightcuts over brute force against the number "
                 "of lights (cf. Figure 4)", fontsize="medium")
    ax.grid(True, which="major", alpha=0.5)
    ax.grid(True, which="minor", alpha=0.15)
    ax.legend(fontsize="small", loc="best")
    fig.tight_layout()
    path = out_dir / "speedup.png"
    fig.savefig(path)
    plt.close(fig)
    return path, skipped


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Plot error-against-time and Lightcuts speed-up figures "
                    "from vrlcuts benchmark CSVs.")
    parser.add_argument("--results", required=True,
                        help="results.csv, one row per point (a point of several renders: their mean time and root-mean-square RMSE, with rmse_min and rmse_max)")
    parser.add_argument("--speedup",
                        help="speedup.csv (optional; skipped when absent "
                             "or without rows)")
    parser.add_argument("--out", required=True,
                        help="output directory (created if needed)")
    args = parser.parse_args(argv)

    results = read_csv(args.results, RESULTS_REQUIRED, RESULTS_COLUMNS,
                       "results")
    speedup_rows = None
    if args.speedup:
        if pathlib.Path(args.speedup).is_file():
            if pathlib.Path(args.speedup).stat().st_size > 0:
                speedup_rows = read_csv(args.speedup, SPEEDUP_REQUIRED,
                                        SPEEDUP_COLUMNS, "speedup")
            else:
                print("note: speedup file %s is empty; no speedup.png"
                      % args.speedup, file=sys.stderr)
        else:
            print("note: speedup file %s not found; no speedup.png"
                  % args.speedup, file=sys.stderr)

    plt = import_pyplot()

    out_dir = pathlib.Path(args.out)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        die("cannot create output directory %s: %s" % (out_dir, exc))

    if not results:
        print("note: %s has no data rows; no error-time plots"
              % args.results, file=sys.stderr)

    # Part (d) alone (part = multiple) gets its own plot, error-time-<scene>-d.png.
    by_scene = {}
    for row in results:
        key = row["scene"] + ("-d" if row.get("part") == "multiple" else "")
        by_scene.setdefault(key, []).append(row)

    used_names = {}
    for scene, rows in by_scene.items():
        name = sanitise(scene)
        if name in used_names and used_names[name] != scene:
            print("warning: scenes %r and %r share the file name "
                  "error-time-%s.png; the later one overwrites the earlier"
                  % (used_names[name], scene, name), file=sys.stderr)
        used_names[name] = scene
        path, skipped = plot_scene(plt, scene, rows, out_dir)
        print("wrote %s" % path)
        if skipped:
            print("note: %s: skipped %d panel point(s) with a zero, negative or "
                  "non-finite time or error" % (scene, skipped),
                  file=sys.stderr)

    if speedup_rows is not None:
        if not speedup_rows:
            print("note: speedup file %s has no data rows; no speedup.png"
                  % args.speedup, file=sys.stderr)
        else:
            path, skipped = plot_speedup(plt, speedup_rows, out_dir)
            if path is None:
                print("note: no usable (positive, finite) rows in %s; "
                      "no speedup.png" % args.speedup, file=sys.stderr)
            else:
                print("wrote %s" % path)
            if skipped:
                print("note: skipped %d speedup row(s) with a non-positive "
                      "or non-finite n or speed-up" % skipped,
                      file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
