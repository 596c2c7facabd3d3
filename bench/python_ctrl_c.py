#!/usr/bin/python3
"""Ctrl-C latency of every long Python call against docs/python.md's promise of half a second.

    PYTHONPATH=BUILD/python /usr/bin/python3 bench/python_ctrl_c.py [CASE ...] [--moments 10]

Each case of tests/python/long_calls.py (all of them by default) runs in its own Python: once uninterrupted (its
length), then once per moment with SIGINT sent at that fraction of the length (more moments early than late:
0.02 .. 0.75), the time from the signal to the KeyboardInterrupt measured. Prints, per case, its length, how many
moments interrupted it (a late one may come after a faster run ended), the median and the maximum latency, and
whether a save left its old output whole and no temporary file; a markdown table at the end, for docs/python.md.
The test command (tests/python/test_long_calls.py) checks the same calls once each, against a limit of 2 s.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests" / "python"
sys.path.insert(0, str(TESTS))


def bunny():
    seed = os.environ.get("VOX_SEED_DIR") or subprocess.run([str(ROOT / "scripts" / "seed-dir.sh")],
                                                            capture_output=True, text=True, check=True).stdout.strip()
    return pathlib.Path(seed) / "meshes" / "bun_zipper.ply"


def main():
    from long_calls import CASES
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("cases", nargs="*", default=list(CASES))
    parser.add_argument("--moments", type=int, default=10)
    args = parser.parse_args()
    n = args.moments
    moments = [0.02 + 0.73 * (i / max(n - 1, 1)) ** 2 for i in range(n)]
    rows = []
    for case in args.cases:
        proc = subprocess.run([sys.executable, str(TESTS / "long_calls.py"), case, ",".join(map(str, moments)),
                               str(bunny())], capture_output=True, text=True)
        if proc.returncode != 0:
            print(f"{case}: failed ({proc.returncode}): {proc.stderr.strip()[-300:]}", flush=True)
            rows.append((case, None, 0, None, None, "failed"))
            continue
        r = json.loads(proc.stdout.splitlines()[-1])
        lat = [s for what, s, _ in r["results"] if what == "interrupted"]
        clean = "yes" if not r["changed_files"] and r["old_output_kept"] and r["alive"] else f"NO {r}"
        med, worst = (statistics.median(lat), max(lat)) if lat else (None, None)
        rows.append((case, r["length"], len(lat), med, worst, clean))
        print(f"{case}: length {r['length']:.2f} s, {len(lat)}/{n} interrupted, median "
              f"{med if med is None else round(med, 3)} s, max {worst if worst is None else round(worst, 3)} s, "
              f"clean {clean}", flush=True)
    print("\n| call (long_calls.py case) | uninterrupted | interrupted | median | max |")
    print("|---|---|---|---|---|")
    for case, length, count, med, worst, clean in rows:
        if length is None:
            print(f"| {case} | failed | | | |")
            continue
        fmt = (lambda x: "-" if x is None else f"{x:.3f} s")
        flag = "" if worst is not None and worst < 0.5 else " (over 0.5 s)"
        print(f"| {case} | {length:.1f} s | {count}/{n} | {fmt(med)} | {fmt(worst)}{flag} |")


if __name__ == "__main__":
    main()
