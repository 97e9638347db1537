#!/usr/bin/env python3
"""Input-to-frame latency in the web page while a store refines (a
benchmark, not a test): tests/browser/latency.test.mjs run again and again,
alternating two settings of the page in each round (their order rotated
every round), with input sent through DevTools and, under xvfb-run with
headful Chromium, through the X server as a mouse's would be (XTest). Prints
a table per input path and setting: the median of the runs' medians, the
range of the runs' worsts, per event type, and how many runs kept every
event within two frame budgets (24 ms); then one JSON line.

The settings are page parameters (frontends/web/app.js): by default
`stripshare=0.5` (a store's strips of half the frame budget, as the page
had them before) against the defaults (a quarter); `--before lowlatency=1`
compares a desynchronized (low-latency) WebGL context with the ordinary
one. `--before-site DIR` serves another build of the page for the
baseline (a copy of build-web/site made before a change), so that two
builds are compared in the same alternating run. `--floor` makes the
baseline the floor page instead (TESSERA_LATENCY_FLOOR: the same window,
canvas box and input, each answered by a clear of the canvas and a
one-pixel read-back): what Chromium, its GPU process and the display take
on this machine whatever a page does, so that the page's latencies are
read against the floor measured in the same run. `--floor window` makes it
the floor page on a copy of the page's window (its markup and style sheet,
without its scripts: what presenting the page's controls adds), `--floor
both` runs the two floors and the page in each round.

    /usr/bin/python3 bench/web_latency.py                 # 3 rounds, both input paths
    /usr/bin/python3 bench/web_latency.py --rounds 5 --inputs x11
    cp -r build-web/site /tmp/site-before   # ... change, scripts/web.sh, then:
    /usr/bin/python3 bench/web_latency.py --before '' --before-site /tmp/site-before
    /usr/bin/python3 bench/web_latency.py --inputs x11 --wheel-ms 25   # a wheel spun fast
    /usr/bin/python3 bench/web_latency.py --inputs x11 --floor --rounds 4   # the page against the floor
    /usr/bin/python3 bench/web_latency.py --inputs x11 --floor both --wheel-ms 25   # and the floor in the page's window

Needs build/tessera, build-web/site (scripts/web.sh), tests/browser's
node_modules and, for x11, xvfb-run and libXtst (scripts/setup.sh).
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET_MS = 24.0  # two frame budgets of the page's 12 ms (app.js ?budget=)
TYPES = ("all", "pointermove", "pointerup", "wheel")
SUMMARY = re.compile(r"latency: (?:store refining|the floor page) at \S+, budget [\d.]+ ms: (.*)")
STATS = re.compile(r"(all events|pointermove|pointerup|wheel):? median ([\d.]+) ms, 90th percentile [\d.]+ ms, "
                   r"worst ([\d.]+) ms over (\d+)")


def run_once(query, inputs, log=None, site="", floor=""):
    """One latency test run; {type: (median, worst, n)} from its summary line.
    `log`: a file for the test's output (the worst events explained); `site`:
    the page's build (default build-web/site); `floor`: the floor page ("1",
    or "window": in a copy of the page's window), else the page."""
    env = dict(os.environ, TESSERA_LATENCY_QUERY=query, TESSERA_LATENCY_INPUT=inputs,
               TESSERA_LATENCY_FLOOR=floor or "0",
               TESSERA_CLI=os.environ.get("TESSERA_CLI", os.path.join(ROOT, "build/tessera")))
    if site:
        env["TESSERA_SITE"] = site
    cmd = ["node", "--test", "tests/browser/latency.test.mjs"]
    if inputs == "x11":
        env["TESSERA_HEADFUL"] = "1"
        cmd = ["xvfb-run", "-a"] + cmd
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    if log:
        with open(log, "w") as f:
            f.write(p.stdout + p.stderr)
    m = SUMMARY.search(p.stdout)
    if not m:
        tail = "\n".join((p.stdout + p.stderr).splitlines()[-15:])
        raise RuntimeError(f"latency test ({inputs}, ?{query}) printed no summary (exit {p.returncode}):\n{tail}")
    out = {}
    for name, median, worst, n in STATS.findall(m.group(1)):
        out["all" if name == "all events" else name] = (float(median), float(worst), int(n))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3, help="rounds, each running every setting once per input path")
    ap.add_argument("--inputs", default="devtools,x11", help="input paths: devtools, x11, touch (comma-separated)")
    ap.add_argument("--before", default="stripshare=0.5", help="page parameters of the baseline")
    ap.add_argument("--after", default="", help="page parameters of the setting compared (default: the defaults)")
    ap.add_argument("--before-site", default="", help="the baseline's build of the page (default: build-web/site)")
    ap.add_argument("--floor", nargs="?", const="plain", default="", choices=("plain", "window", "both"),
                    help="the baseline is the floor page (the least a WebGL page can do), not --before; "
                         "window: the floor page in a copy of the page's window; both: the two floors")
    ap.add_argument("--logs", default="", help="a folder for each run's test output (ROUND-INPUT-SETTING.log)")
    ap.add_argument("--wheel-ms", type=float, default=0.0,
                    help="the wheel turns' step in ms (default: the test's, about 200; a wheel spun fast: 20-50)")
    args = ap.parse_args()
    inputs = [i for i in args.inputs.split(",") if i]
    for i in inputs:
        if i not in ("devtools", "x11", "touch"):
            sys.exit(f"web_latency.py: --inputs {i}: devtools, x11 or touch")
    if "x11" in inputs and not shutil.which("xvfb-run"):
        sys.exit("web_latency.py: --inputs x11 needs xvfb-run (scripts/setup.sh installs it)")
    if args.rounds < 1:
        sys.exit("web_latency.py: --rounds must be at least 1")
    if args.floor and args.before_site:
        sys.exit("web_latency.py: --floor is the baseline: it takes no --before-site")
    if args.before_site and not os.path.isfile(os.path.join(args.before_site, "tessera-core.wasm")):
        sys.exit(f"web_latency.py: --before-site {args.before_site}: no web build there (tessera-core.wasm)")
    sites = {"before": os.path.abspath(args.before_site) if args.before_site else "", "after": ""}
    settings = {"before": args.before, "after": args.after}
    # The floor pages by setting name: TESSERA_LATENCY_FLOOR's value.
    floors = {"plain": {"floor": "1"}, "window": {"floor-window": "window"},
              "both": {"floor": "1", "floor-window": "window"}}.get(args.floor, {})
    if floors:
        sites = {**{f: "" for f in floors}, "after": ""}
        settings = {**{f: "" for f in floors}, "after": args.after}
    if args.logs:
        os.makedirs(args.logs, exist_ok=True)
    if args.wheel_ms > 0:
        os.environ["TESSERA_LATENCY_WHEEL_MS"] = str(args.wheel_ms)
    runs = {(i, s): [] for i in inputs for s in settings}
    t0 = time.time()
    for r in range(args.rounds):
        names = list(settings)
        order = names[r % len(names):] + names[:r % len(names)]  # each first in turn
        for i in inputs:
            for s in order:
                log = os.path.join(args.logs, f"{r + 1}-{i}-{s}.log") if args.logs else None
                res = run_once(settings[s], i, log, sites[s], floor=floors.get(s, ""))
                runs[(i, s)].append(res)
                a = res["all"]
                print(f"round {r + 1}/{args.rounds} {i:8} {s:12} all events median {a[0]:.1f} ms, worst {a[1]:.1f} ms "
                      f"({time.time() - t0:.0f} s)", file=sys.stderr, flush=True)

    def cell(rs, t):
        got = [x[t] for x in rs if t in x]
        if not got:
            return "-"
        med = statistics.median(g[0] for g in got)
        worsts = [g[1] for g in got]
        return f"{med:.1f} ({min(worsts):.1f}-{max(worsts):.1f})"

    print(f"\nInput-to-frame latency while a store refines, ms: median of the runs' medians "
          f"(range of the runs' worsts); {args.rounds} alternating rounds")
    if floors:
        print("floor: the floor page (a clear and a one-pixel read-back per input)   " if "floor" in floors else "", end="")
        print("floor-window: the same, in a copy of the page's window   " if "floor-window" in floors else "", end="")
        print(f"after: the page, ?{settings['after'] or '(defaults)'}\n")
    else:
        print(f"before: ?{settings['before'] or '(defaults)'}{' of ' + sites['before'] if sites['before'] else ''}   "
              f"after: ?{settings['after'] or '(defaults)'}\n")
    head = ["input", "setting"] + [t if t != "all" else "all events" for t in TYPES] + [f"runs worst <= {TARGET_MS:.0f}"]
    rows = []
    for (i, s), rs in runs.items():
        met = sum(1 for x in rs if x["all"][1] <= TARGET_MS)
        rows.append([i, s] + [cell(rs, t) for t in TYPES] + [f"{met} of {len(rs)}"])
    widths = [max(len(str(c)) for c in col) for col in zip(head, *rows)]
    for line in [head, ["-" * w for w in widths]] + rows:
        print(" | ".join(str(c).ljust(w) for c, w in zip(line, widths)))
    print(json.dumps({"rounds": args.rounds, "settings": settings, "sites": sites, "target_ms": TARGET_MS,
                      "runs": {f"{i}/{s}": rs for (i, s), rs in runs.items()}}))


if __name__ == "__main__":
    main()
