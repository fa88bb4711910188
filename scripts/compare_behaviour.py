"""Compare two recordings of ``scripts/record_behaviour.py``: is the command line's behaviour unchanged?

``python scripts/compare_behaviour.py A B [--paths N]`` prints one line per recorded call (and per report),
``identical`` or ``differs`` followed by the first ``N`` differing JSON paths with both values, and exits 1 if
any call differs or is missing from one side (0 otherwise).

The fixed-point loop's feed-forward words (``feedforward-words.json``) are compared tick by tick: the table may be
computed within a stated tolerance (issue 42 item 2), which shows only where it moves a Q15 word across a rounding
boundary. Those ticks are counted and listed (case, tick, leg, both words) beside each side's engine; they are the
tolerance, not a difference, and a recording without them is not compared. Every other record stays exact.

Equality is exact: the same JSON types (an int is not a float, a bool is not an int), numbers bit for bit
(JSON numbers parse to the shortest round-tripping float, so equal text means equal bits), strings and
list lengths identical. Only the run-dependent fields listed in ``VOLATILE_KEYS``, ``VOLATILE_COLUMNS``,
``VOLATILE_HASHES``, ``REPORT_IGNORED`` and ``TEXT_SUBSTITUTIONS`` are removed before comparing, each with its
reason; nothing else. Standard library only.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

# Dict keys removed wherever they occur (stdout JSON, written JSON/JSON-lines files, report checks).
VOLATILE_KEYS = {
    "run_wall_s": "montecarlo summary: sum/mean of the runs' wall-clock times",
    "wall_s": "montecarlo row (row.json, montecarlo.partial.jsonl): one run's wall-clock time",
    "real_time_factor": "simulate summary (stdout JSON, summary.json): duration_s / wall_s, a wall-clock rate",
}
# Columns removed from recorded CSV files (``csv_header``/``csv_rows``) and Parquet tables (``parquet``).
VOLATILE_COLUMNS = {
    "wall_s": "montecarlo results.csv / results.parquet: each run's wall-clock time",
}
# Files whose SHA-256 in an output folder's ownership manifest (``.stewart-drake-manifest.json``) is not compared: the
# file's own text is, less its volatile keys.
VOLATILE_HASHES = {
    "summary.json": "simulate: its text carries wall_s and real_time_factor, so its hash differs from run to run",
}
# Dict keys a later tree adds: absent from A and present in B, they are listed, not counted as a difference.
ADDED_KEYS = {
    "feedforward_engine": "simulate summary: the inverse dynamics of the feed-forward table, c or numpy (issue 42)",
}
FEEDFORWARD_WORDS = "feedforward-words.json"
# Fields of the report records (``report-quick``, ``report-full``) not compared.
REPORT_IGNORED = {
    "stdout": "the report's summary line carries its wall time",
    "stderr": "progress lines carry wall/CPU times and arrive in the order the worker processes finish",
}
# Regular-expression substitutions applied to every string before comparing.
TEXT_SUBSTITUTIONS = [
    (
        re.compile(r"http://(localhost|127\.0\.0\.1):\d+"),
        r"http://\1:<PORT>",
        "view / Meshcat: the port is the first free one from 7000, which depends on other processes",
    ),
    (
        re.compile(r"in [0-9.e+-]+ s of wall time \([0-9.e+-]+ × real time\)"),
        "in <WALL> s of wall time (<RATE> × real time)",
        "simulate's last stderr line: the run's wall-clock time and real-time factor (summary.json's wall_s and "
        "real_time_factor)",
    ),
]


def _subst(s: str) -> str:
    for pattern, repl, _ in TEXT_SUBSTITUTIONS:
        s = pattern.sub(repl, s)
    return s


def _drop_columns(table: dict) -> dict:
    """A recorded CSV (header + rows of strings) or Parquet table without the volatile columns."""
    if "csv_header" in table:
        keep = [i for i, h in enumerate(table["csv_header"]) if h not in VOLATILE_COLUMNS]
        return {
            "csv_header": [table["csv_header"][i] for i in keep],
            "csv_rows": [[r[i] if i < len(r) else None for i in keep] for r in table["csv_rows"]],
        }
    if "parquet" in table and isinstance(table["parquet"], dict):
        p = table["parquet"]
        return {
            "parquet": {
                "schema": [f for f in p.get("schema", []) if f.split(":")[0] not in VOLATILE_COLUMNS],
                "columns": {k: v for k, v in p.get("columns", {}).items() if k not in VOLATILE_COLUMNS},
            }
        }
    return table


def clean(obj):
    """``obj`` without the volatile fields (see the module docstring)."""
    if isinstance(obj, str):
        return _subst(obj)
    if isinstance(obj, list):
        return [clean(v) for v in obj]
    if isinstance(obj, dict):
        if "csv_header" in obj or "parquet" in obj:
            obj = _drop_columns(obj)
        return {k: clean(v) for k, v in obj.items() if k not in VOLATILE_KEYS}
    return obj


def _drop_volatile_hashes(rec: dict) -> None:
    """Remove the ``VOLATILE_HASHES`` from the ownership manifests among a call's files."""
    for name, content in rec.get("files", {}).items() if isinstance(rec.get("files"), dict) else ():
        if name.endswith(".stewart-drake-manifest.json") and isinstance(content, dict):
            for entry, meta in content.get("files", {}).items():
                if entry in VOLATILE_HASHES and isinstance(meta, dict):
                    meta.pop("sha256", None)


def load(path: Path) -> dict:
    rec = json.loads(path.read_text(encoding="utf-8"))
    _drop_volatile_hashes(rec)
    if path.stem.startswith("report-"):
        rec = {k: v for k, v in rec.items() if k not in REPORT_IGNORED}
    return clean(rec)


ADDED: set[str] = set()  # the ``ADDED_KEYS`` met in B without A


def diff(a, b, path: str = "$") -> list[tuple[str, object, object]]:
    """Every differing leaf as (JSON path, value in A, value in B); ``<absent>`` for a missing key/item."""
    if type(a) is not type(b):
        return [(path, a, b)]
    if isinstance(a, dict):
        out = []
        ADDED.update(k for k in b if k not in a and k in ADDED_KEYS)
        for k in list(a) + [k for k in b if k not in a and k not in ADDED_KEYS]:
            sub = f"{path}.{k}" if k.isidentifier() else f"{path}[{json.dumps(k, ensure_ascii=False)}]"
            out += diff(a[k], b[k], sub) if k in a and k in b else [(sub, a.get(k, "<absent>"), b.get(k, "<absent>"))]
        return out
    if isinstance(a, list):
        out = []
        for i in range(max(len(a), len(b))):
            if i < len(a) and i < len(b):
                out += diff(a[i], b[i], f"{path}[{i}]")
            else:
                out.append((f"{path}[{i}]", a[i] if i < len(a) else "<absent>", b[i] if i < len(b) else "<absent>"))
        return out
    if isinstance(a, str) and a != b and ("\n" in a or "\n" in b):
        # Multi-line text (a raw stdout): the first differing line, not the whole text.
        la, lb = a.splitlines(), b.splitlines()
        bad = [k for k in range(max(len(la), len(lb))) if k >= len(la) or k >= len(lb) or la[k] != lb[k]]
        i = bad[0]
        return [
            (
                f"{path} line {i + 1} (first of {len(bad)} differing lines)",
                la[i] if i < len(la) else "<absent>",
                lb[i] if i < len(lb) else "<absent>",
            )
        ]
    return [] if a == b else [(path, a, b)]


def _short(v, n: int = 160) -> str:
    s = json.dumps(v, ensure_ascii=False) if not isinstance(v, str) or v != "<absent>" else v
    return s if len(s) <= n else s[: n - 3] + "..."


def boundary_ticks(a: dict, b: dict) -> tuple[list[str], list[tuple[str, int, int, int, int]]]:
    """Two ``feedforward-words.json`` records: ``(problems, ticks)``, the cases that cannot be compared (missing,
    an error, another number of ticks) and every (case, tick, leg, word in A, word in B) whose words differ."""
    problems, ticks = [], []
    ca, cb = a.get("cases", {}), b.get("cases", {})
    for case in sorted(set(ca) | set(cb)):
        wa, wb = ca.get(case, {}).get("words"), cb.get(case, {}).get("words")
        if not isinstance(wa, list) or not isinstance(wb, list) or len(wa) != len(wb):
            problems.append(case if case in ca and case in cb else f"{case} (missing on one side)")
            continue
        ticks += [
            (case, k, j + 1, x, y)
            for k, (ra, rb) in enumerate(zip(wa, wb))
            for j, (x, y) in enumerate(zip(ra, rb))
            if x != y
        ]
    for side in (ca, cb):
        if "error" in side:
            problems.append(f"error: {side['error']}")
    return problems, ticks


def compare_feedforward_words(a: Path, b: Path, shown: int) -> bool:
    """Print the feed-forward words' comparison (see the module docstring); False where they cannot be compared."""
    ra, rb = (json.loads(p.read_text(encoding="utf-8")) for p in (a, b))
    problems, ticks = boundary_ticks(ra, rb)
    engines = {
        s: sorted({c.get("engine", "?") for c in r.get("cases", {}).values() if isinstance(c, dict)})
        for s, r in (("A", ra), ("B", rb))
    }
    n = sum(len(c.get("words", [])) for c in rb.get("cases", {}).values() if isinstance(c, dict))
    print(
        f"feedforward-words: {len(ticks)} boundary tick{'s' if len(ticks) != 1 else ''} in {n} ticks "
        f"(engines A {'/'.join(engines['A'])}, B {'/'.join(engines['B'])})"
        + (f"; not comparable: {', '.join(problems)}" if problems else "")
    )
    for case, k, leg, x, y in ticks[:shown]:
        print(f"    {case} tick {k} leg {leg}: {x}  !=  {y}")
    return not problems


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path, help="a recording folder (the reference)")
    ap.add_argument("b", type=Path, help="a recording folder (the one to check)")
    ap.add_argument("--paths", type=int, default=5, help="differing paths shown per call (default 5)")
    args = ap.parse_args(argv)
    for d in (args.a, args.b):
        if not d.is_dir():
            print(f"compare_behaviour: {d} is not a folder", file=sys.stderr)
            return 2

    def names(d: Path) -> set[str]:
        return {p.name for p in d.glob("*.json") if p.name not in ("manifest.json", FEEDFORWARD_WORDS)}

    na, nb = names(args.a), names(args.b)
    bad = 0
    for name in sorted(na | nb):
        label = name[:-5]
        if name not in nb or name not in na:
            print(f"{label}: missing in {args.b if name not in nb else args.a}")
            bad += 1
            continue
        d = diff(load(args.a / name), load(args.b / name))
        if not d:
            print(f"{label}: identical")
            continue
        bad += 1
        print(f"{label}: differs ({len(d)} path{'s' if len(d) != 1 else ''})")
        for path, va, vb in d[: args.paths]:
            print(f"    {path}: {_short(va)}  !=  {_short(vb)}")
    total = len(na | nb)
    if (args.a / FEEDFORWARD_WORDS).is_file() and (args.b / FEEDFORWARD_WORDS).is_file():
        total += 1
        bad += not compare_feedforward_words(args.a / FEEDFORWARD_WORDS, args.b / FEEDFORWARD_WORDS, args.paths)
    for k in sorted(ADDED):
        print(f"added in {args.b}: {k} ({ADDED_KEYS[k]})")
    print(f"{total - bad}/{total} identical" + (f", {bad} differ or are missing" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
