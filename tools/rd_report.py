#!/usr/bin/env python3
"""Rate–distortion yardstick: dmc's default ladder on every sequence of ../shared/data, against
the committed baseline (bench/rd/baseline.csv). RD.md, "Rate–distortion yardstick", explains it.

The measuring and the maths are `dmc sweep --baseline FILE` (BD-rates, interpolated rates and the
per-element bytes, tested in tests/unit/sweep); this script only runs it once per sequence, in
parallel, and gathers the per-sequence answers into one table and a summary line.

  tools/rd_report.py --dmc build/bin/dmc                  # compare the build with the baseline
  tools/rd_report.py --dmc build/bin/dmc --make-baseline  # rewrite bench/rd/baseline.csv
"""

import argparse
import concurrent.futures
import json
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_DATA = REPO.parent / "shared" / "data"
DEFAULT_BASELINE = REPO / "bench" / "rd" / "baseline.csv"

# (name in the yardstick, input relative to the data directory, whole capture?)
SEQUENCES = [
    ("horse-gallop", "horse-gallop", False),
    ("samba", "samba", False),
    ("crane", "crane", False),
    ("chicken-crossing", "chicken-crossing", False),
    ("cow", "cow", False),
    ("dance", "dance", False),
    ("jump", "jump", False),
    ("elephant-gallop", "elephant-gallop", False),
    ("horse-collapse", "horse-collapse", False),
    ("crane-full", "crane-full/crane-full.pc2", True),
    ("jump-full", "jump-full/jump-full.pc2", True),
    ("elephant-gallop-full", "elephant-gallop-full/elephant-gallop-full.pc2", True),
]

# The baseline's ladder: residual bits 7 to 16 in half bits, which spans STED from above 0.05 to
# below 0.01 on every sequence above (basis bits follow the rung as in every dmc sweep).
BASELINE_LADDER = [7 + 0.5 * k for k in range(19)]
STED_TARGETS = [0.01, 0.02, 0.05]
BREAKDOWN_STED = 0.02
ELEMENTS = ["residuals", "basis", "operator", "connectivity", "anchors", "mean", "header"]


def run_sweep(dmc, name, path, out_dir, baseline, ladder, extra):
    """One `dmc sweep` of one sequence; returns (name, its JSON report, seconds)."""
    command = [str(dmc), "sweep", str(path), "-o", str(out_dir / name), "--operators", "ddl",
               "--baselines", "none", "--sequence", name, "--json",
               "--sted-targets", ",".join(f"{t:g}" for t in STED_TARGETS),
               "--breakdown-sted", f"{BREAKDOWN_STED:g}", *extra]
    if baseline is not None:
        command += ["--baseline", str(baseline)]
    if ladder is not None:
        command += ["--ladder", ",".join(f"{b:g}" for b in ladder)]
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    seconds = time.monotonic() - start
    if done.returncode != 0:
        raise RuntimeError(f"{name}: dmc sweep exited {done.returncode}: {done.stderr.strip()}")
    return name, json.loads(done.stdout), seconds


def rate_cell(rate):
    value = rate["bpfv"]
    if rate["kind"] == "interpolated":
        return f"{value:.3g}"
    if rate["kind"] == "below-range":
        return f"≤ {value:.3g}"
    return f"> {value:.3g}" if value > 0 else "–"


def percent_cell(value):
    return "–" if value is None else f"{value:+.1f} %"


def shares(row):
    total = row["bytes"]
    return " / ".join(f"{100.0 * row['breakdown'][e] / total:.0f}" for e in ELEMENTS)


def git(*args):
    done = subprocess.run(["git", "-C", str(REPO), *args], capture_output=True, text=True,
                          check=False)
    # Only trailing whitespace: a porcelain status line starts with a meaningful space.
    return done.stdout.rstrip() if done.returncode == 0 else ""


def dmc_version(dmc):
    done = subprocess.run([str(dmc), "--version"], capture_output=True, text=True, check=False)
    return done.stdout.strip()


def summary(label, values):
    values = [v for v in values if v is not None]
    if not values:
        return f"{label}: –"
    return (f"{label}: worst {max(values):+.1f} %, mean {sum(values) / len(values):+.1f} % "
            f"({len(values)} sequences)")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dmc", default=str(REPO / "build" / "bin" / "dmc"),
                        help="the dmc binary to measure (default: build/bin/dmc)")
    parser.add_argument("--data", default=str(DEFAULT_DATA),
                        help="the shared data directory (default: ../shared/data)")
    parser.add_argument("--baseline", default=str(DEFAULT_BASELINE),
                        help="the yardstick CSV to compare with (default: bench/rd/baseline.csv)")
    parser.add_argument("--sequences", default="",
                        help="comma-separated subset of: " + ",".join(s[0] for s in SEQUENCES))
    parser.add_argument("--jobs", type=int, default=1,
                        help="sweeps run at once (each also uses the codec's own threads)")
    parser.add_argument("-o", "--output", default="/tmp/dmc-rd-report",
                        help="directory for each sweep's files (default: /tmp/dmc-rd-report)")
    parser.add_argument("--sweep-args", default="",
                        help="further `dmc sweep` options for every sequence, one string "
                             "(e.g. \"--encoder-option residual_rdo_lambda=0.1\"), to measure a non-default "
                             "setting")
    parser.add_argument("--make-baseline", action="store_true",
                        help="run the baseline ladder and write --baseline instead of comparing")
    args = parser.parse_args()

    dmc = Path(args.dmc)
    if not dmc.is_file():
        sys.exit(f"rd_report: no dmc binary at {dmc} (--dmc)")
    wanted = [s for s in args.sequences.split(",") if s]
    known = {s[0] for s in SEQUENCES}
    unknown = [s for s in wanted if s not in known]
    if unknown:
        sys.exit(f"rd_report: unknown sequence(s) {', '.join(unknown)}; known: "
                 + ", ".join(s[0] for s in SEQUENCES))
    if args.jobs < 1:
        sys.exit("rd_report: --jobs must be at least 1")
    baseline = Path(args.baseline)
    if not args.make_baseline and not baseline.is_file():
        sys.exit(f"rd_report: no baseline at {baseline} (--baseline, or --make-baseline)")
    out_dir = Path(args.output)
    out_dir.mkdir(parents=True, exist_ok=True)

    runs = []
    for name, relative, whole in SEQUENCES:
        if wanted and name not in wanted:
            continue
        path = Path(args.data) / relative
        if not path.exists():
            print(f"rd_report: {name} skipped: {path} is absent", file=sys.stderr)
            continue
        runs.append((name, path, whole))
    if not runs:
        sys.exit("rd_report: no sequence to run")

    start = time.monotonic()
    reports, seconds = {}, {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [
            pool.submit(run_sweep, dmc, name, path, out_dir,
                        None if args.make_baseline else baseline,
                        BASELINE_LADDER if args.make_baseline else None,
                        shlex.split(args.sweep_args))
            for name, path, _ in runs
        ]
        failed = False
        for future in concurrent.futures.as_completed(futures):
            try:
                name, report, took = future.result()
            except (RuntimeError, json.JSONDecodeError) as error:
                print(f"rd_report: {error}", file=sys.stderr)
                failed = True
                continue
            reports[name], seconds[name] = report, took
            print(f"rd_report: {name} done in {took:.0f} s", file=sys.stderr)
    wall = time.monotonic() - start
    if failed:
        sys.exit(1)

    commit = git("rev-parse", "HEAD")
    dirty = git("status", "--porcelain", "--untracked-files=no")
    tree = "clean" if not dirty else "modified: " + " ".join(
        line[3:] for line in dirty.splitlines())
    if args.make_baseline:
        header, rows = None, []
        for name, _, _ in runs:
            lines = (out_dir / name / "yardstick.csv").read_text().splitlines()
            body = [line for line in lines if line and not line.startswith("#")]
            header = header or body[0]
            if body[0] != header:
                sys.exit(f"rd_report: {name}/yardstick.csv has another header")
            rows += body[1:]
        meta = [
            "dmc rate-distortion yardstick: the default ladder of every sequence (RD.md, "
            "\"Rate-distortion yardstick\")",
            f"commit: {commit}",
            f"tree: {tree}",
            f"dmc: {dmc_version(dmc)}",
            "ladder: residual bits " + ",".join(f"{b:g}" for b in BASELINE_LADDER)
            + " (basis bits clamp(round(bits), 10, 16)), operator ddl, effort 2",
            "made by: tools/rd_report.py --make-baseline",
        ]
        text = "".join(f"# {m}\n" for m in meta) + header + "\n" + "\n".join(rows) + "\n"
        baseline.parent.mkdir(parents=True, exist_ok=True)
        baseline.write_text(text)
        print(f"wrote {baseline}: {len(rows)} points of {len(runs)} sequences, commit {commit} "
              f"({tree}), {wall:.0f} s with --jobs {args.jobs}")
        return

    print(f"dmc {dmc} at commit {commit} ({tree}) against {baseline}\n")
    targets = " | ".join(f"bpfv @ {t:g} (baseline)" for t in STED_TARGETS)
    print(f"| sequence | V × F | BD-rate STED | BD-rate KG | {targets} | "
          f"near STED {BREAKDOWN_STED:g}: bits, STED, bpfv, rank | % "
          + " / ".join(ELEMENTS) + " |")
    print("|---|---|---:|---:|" + "---:|" * len(STED_TARGETS) + "---|---|")
    bd = {(whole, metric): [] for whole in (True, False) for metric in ("sted", "kg")}
    for name, _, whole in runs:
        report = reports[name]
        comparison = report["comparisons"][0]
        near = comparison["current_near"]
        cells = " | ".join(f"{rate_cell(t['current'])} ({rate_cell(t['baseline'])})"
                           for t in comparison["targets"])
        print(f"| {name} | {report['vertices']} × {report['frames']} | "
              f"{percent_cell(comparison['bd_rate_sted'])} | "
              f"{percent_cell(comparison['bd_rate_kg'])} | {cells} | "
              f"{near['residual_bits']:g}, {near['sted']:.4f}, {near['bpfv']:.3f}, "
              f"{near['rank']} | {shares(near)} |")
        for metric in ("sted", "kg"):
            bd[(whole, metric)].append(comparison["bd_rate_" + metric])
    print()
    for metric, label in (("sted", "STED"), ("kg", "KG")):
        print(summary(f"BD-rate ({label}) over whole captures", bd[(True, metric)]) + "; "
              + summary("over short excerpts", bd[(False, metric)]))
    print(f"{len(runs)} sequences in {wall:.0f} s with --jobs {args.jobs}")


if __name__ == "__main__":
    main()
