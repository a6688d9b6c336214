"""Command line of the sweep tool.

    cd scripts
    /usr/bin/python3 -m sweep run (--preset NAME | --spec FILE.json) --output DIR [--build-dir B]
                                  [--only TEXT] [--dry-run] [--rerun] [--markdown X.md] [--png X.png]
    /usr/bin/python3 -m sweep report DIR [--markdown X.md] [--png X.png] [--tolerance 0.05] [--refresh]
    /usr/bin/python3 -m sweep stability DIR [--markdown X.md] [--png X.png] [--refresh]
    /usr/bin/python3 -m sweep presets

`run` runs one setting at a time (niced, one thread per program) and keeps each result in
DIR/<label>/result.json, so an interrupted sweep continues where it stopped; `report` and
`stability` read those results only; `run` with --markdown/--png then writes the spec's own
report (its "report" key: "report" for speed against accuracy, "stability" for the map).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import plan, presets, report, stability

REPO = Path(__file__).resolve().parents[2]


def _spec(args) -> dict:
    if args.preset:
        if args.preset not in presets.PRESETS:
            raise SystemExit(f"sweep: preset '{args.preset}': allowed {', '.join(presets.PRESETS)}")
        return presets.PRESETS[args.preset]
    try:
        return json.loads(Path(args.spec).read_text())
    except (OSError, json.JSONDecodeError) as error:
        raise SystemExit(f"sweep: spec file '{args.spec}': {error}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sweep", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run the settings of a sweep")
    source = run.add_mutually_exclusive_group(required=True)
    source.add_argument("--preset")
    source.add_argument("--spec", type=Path)
    run.add_argument("--output", type=Path, required=True)
    run.add_argument("--build-dir", type=Path, default=REPO / "build")
    run.add_argument("--only", help="run only the settings whose label contains this text")
    run.add_argument("--dry-run", action="store_true", help="write the case files only")
    run.add_argument("--rerun", action="store_true", help="run settings again even when a result exists")
    run.add_argument("--markdown", type=Path, help="then write the spec's report (table) here")
    run.add_argument("--png", type=Path, help="then draw the spec's chart here")
    for name in ("report", "stability"):
        p = sub.add_parser(name)
        p.add_argument("output", type=Path)
        p.add_argument("--markdown", type=Path)
        p.add_argument("--png", type=Path)
        p.add_argument("--refresh", action="store_true",
                       help="derive metrics and endings again from the run folders (costs are kept)")
        if name == "report":
            p.add_argument("--tolerance", type=float, default=0.05)
    sub.add_parser("presets")
    args = parser.parse_args(argv)

    if args.command == "presets":
        for name, spec in presets.PRESETS.items():
            print(f"{name}: {len(plan.expand(spec))} runs, {spec['span']}")
        return 0
    if args.command == "run":
        spec = _spec(args)
        plan.execute(spec, args.output, args.build_dir.resolve(), only=args.only, dry_run=args.dry_run,
                     rerun=args.rerun)
        if args.dry_run or not (args.markdown or args.png):
            return 0
        args.command, args.refresh, args.tolerance = spec.get("report", "report"), False, 0.05
    results = plan.load_results(args.output, refresh=args.refresh)
    if args.command not in ("report", "stability"):
        raise SystemExit(f"sweep: report kind '{args.command}': allowed report, stability")
    if not results:
        raise SystemExit(f"sweep: no results (*/result.json) in {args.output}")
    spec_path = args.output / "spec.json"
    spec = json.loads(spec_path.read_text()) if spec_path.exists() else {}
    if args.command == "report":
        text = report.markdown(results, plan.finest_label(spec), args.tolerance)
        if args.png:
            report.chart(results, args.png, plan.finest_label(spec))
    else:
        order = list(dict.fromkeys(entry.get("group", "runs") for entry in spec.get("runs", [])))
        text = stability.markdown(results, order)
        if args.png:
            stability.chart(results, args.png, order=order)
    if args.markdown:
        args.markdown.write_text(text)
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
