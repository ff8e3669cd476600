"""When, at which commit and on which machine a benchmark ran: stored with every result file the
benches write (build/bench-results/*.json, build/quality/targets.json) and printed at the top of
each table of bench/README.md by make_readme_tables.py."""
import datetime
import os
import platform
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _git(*args):
    return subprocess.run(["git", "-C", str(ROOT), *args], text=True, capture_output=True).stdout.strip()


def machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}"


def run_stamp():
    """date (UTC), commit (short; ' (modified)' for a tree with changes outside the files the
    benches write) and machine (processor, cores, load average) of a run starting now."""
    dirty = _git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!bench/README.md", ":!bench/quality-plots",
                 ":!bench/img/terrain-compare.png")
    return {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "commit": _git("rev-parse", "--short", "HEAD") + (" (modified)" if dirty else ""),
            "machine": machine()}


def stamp_line(stamp, method):
    """The first line of a README table: `date, commit C, machine; method.`"""
    return f"{stamp['date']}, commit {stamp['commit']}, {stamp['machine']}; {method}."
